"""The simulated set-ups of the chapter 6 experiments: where the robot starts, where the trash
bin (marker F2) stands and where the obstacles are, in the simulator's world frame.

The dissertation's set-up (``seed`` None) starts at ``wbc.geometry.scenarios.HOME``. The bin stands
under the pose of ``REACH_GOAL`` (pose and position experiments, 6.2.1 and 6.2.2), or
``OBSTACLE_SHIFT`` further, past ``wbc.geometry.scenarios.OBSTACLE`` (6.2.3); the goal is then
x_d = x_2 x_d^2 with the scene's offset x_d^2 (eq. 6.3). A seed draws the start and the bin
from ``START_RANGE`` and ``BIN_RANGE`` around them: the goal stays a pose the arm reaches
above some base pose (the bin only moves and turns on the floor), inside the joint limits.

'table' reaches over the edge of ``wbc.geometry.scenarios.TABLE`` from ``TABLE_START`` to the
gripper of ``TABLE_GOAL``: its marker lies on the table top, under that gripper, and the set-up
carries its own offset x_d^2 (``goal_offset``) and the table (``solids``), which a profile's
scene declares; a seed draws the bin from ``TABLE_BIN_RANGE`` (along the edge more than
across it: the base must stop short of the table).

These configurations are Little John's (``DECLARED_FOR``). Another robot's set-up is derived
from its description (``derived``): it starts at the origin with its arm bent away from the
middle of its joint ranges, and its goal is the pose of its gripper at another configuration
inside its limits (its first joint turned so that the gripper lies ahead, ``_ahead``), the base
``AHEAD`` of the start (a fixed base's where it starts): a goal it reaches by construction.
The bin lies under that pose and the set-up carries its own offset, as 'table''s does. 'pose',
'position' and, on a mobile base small enough for the camera's view to hold the way past the
obstacle, 'obstacle' are derived; the other set-ups are Little John's scenes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.geometry.obstacles3d import Solid
from wbc.geometry.scenarios import HOME, OBSTACLE, REACH_GOAL, TABLE, TABLE_GOAL, TABLE_START
from wbc.planar import offset_of, offset_pose, planar_of, planar_pose
from wbc.robot import MobileManipulator

SEED_MAX = 2**31
"""Seeds of a set-up and of the simulator's noise: 0 to SEED_MAX (numpy's RandomState bound)."""
NAMES = ("pose", "position", "obstacle", "anywhere", "blocked", "table")
"""The experiments of section 6.2; 'anywhere': a pose goal behind the robot, past an obstacle,
which the LP law reaches only under the staging supervisor (deploy/sim_supervised); 'blocked':
the same goal from farther away, with the obstacle on the straight way to it; 'table': a pose
goal over a table's edge, which the arm reaches without touching it."""

ANYWHERE_START = (1.3, 0.2, 0.0)
"""The base of 'anywhere' (x, y, phi): at the far side of the camera's view, facing away."""
ANYWHERE_BIN = (0.35, 0.0)
"""The bin of 'anywhere' (x, y), behind the robot; it faces the other way from the pose
experiment's bin, so the gripper must point back along -x."""
ANYWHERE_OBSTACLE = Circle(0.8, -0.3, 0.1)
"""Beside the way back."""
BLOCKED_START = (1.9, 0.1, 0.0)
"""The base of 'blocked': at the edge of the camera's view, facing away from the bin."""
BLOCKED_OBSTACLE = Circle(1.45, 0.08, 0.1)
"""On the straight way from 'blocked''s start to where the base stands for the bin, clear of
the start's body and of the staging point's by the LP's margin."""

OBSTACLE_SHIFT = (0.75, 0.25)
"""Where the obstacle experiment's bin stands from the pose experiment's, m: past the obstacle."""

START_RANGE = np.array([0.05, 0.05, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1])
"""A seeded start is HOME + U(-range, range), per coordinate (m, m, rad, rad...)."""

BIN_RANGE = np.array([0.1, 0.1, 0.2])
"""A seeded bin is the set-up's + U(-range, range) in (x, y, yaw) (m, m, rad)."""
TABLE_BIN_RANGE = np.array([0.03, 0.1, 0.2])
"""The same for 'table'."""

DECLARED_FOR = "little_john"
"""The robot whose configurations ``wbc.geometry.scenarios`` declares (by its description's
name); every other robot's set-up is ``derived``."""
DERIVED = ("pose", "position", "obstacle")
"""The set-ups derived for another robot ('obstacle' on a mobile base)."""
AHEAD = (0.45, 0.05, -0.15)
"""A derived goal's base (x, y, phi) from the start's, m and rad."""
START_BEND = 0.3
GOAL_BEND = 0.6
"""How far a derived start's and goal's revolute joints sit from the middle of their ranges,
rad, in alternating directions (different ones for the goal); a prismatic joint's, as a share
of its range (``_bent``); every joint stays inside ``LIMIT_SHARE`` of its range."""
LIMIT_SHARE = 0.8
"""The share of each joint's range, about its middle, a derived configuration stays in."""
OBSTACLE_MARGIN_M = 0.1
"""A derived 'obstacle' set-up's least gap between the obstacle and the base's body at the start
and at the goal's base (``_obstacle_way``)."""
OBSTACLE_WAY_MAX_M = 1.5
"""The longest way ``_obstacle_way`` may take, m: beyond it the bin leaves the ceiling camera's
view, and a robot whose body needs more has no 'obstacle' set-up."""
DRAW = 0.1
"""A seed moves a derived start's and goal's arm joints by U(-DRAW, DRAW) rad (a prismatic
joint by that share of its range), and a mobile base's as ``START_RANGE``."""


@dataclass(frozen=True)
class SimScenario:
    """One experiment's set-up: the task, the start q, the bin (x, y, yaw) and obstacles."""

    name: str
    task: str
    start: tuple[float, ...]
    bin: tuple[float, float, float]
    obstacles: tuple[Circle, ...]
    solids: tuple[Solid, ...] = ()
    """Obstacles in 3-D, in the simulator's world frame."""
    goal_height: float | None = None
    """The height of the bin marker's face, m; None: the scene's."""
    goal_offset: tuple[float, ...] | None = None
    """x_d^2 of eq. 6.3 (x, y, z, yaw, pitch, roll); None: the scene's."""

    def sim_params(self) -> dict[str, list]:
        """The simulator's parameters that place this set-up (to the micrometre and the
        microradian)."""
        return {
            "start": [round(float(v), 6) for v in self.start],
            "goal_marker": [round(float(v), 6) for v in self.bin],
            "obstacles": [[float(c.x), float(c.y), float(c.radius)] for c in self.obstacles],
        }

    def goal(self, height_m: float, offset: Sequence[float]) -> np.ndarray:
        """This set-up's x_d (``goal_above``), for the bin marker at ``height_m`` and the
        scene's ``offset`` x_d^2: the goal of a kinematic run of the set-up."""
        return goal_above(self.bin, height_m, offset)


def goal_above(bin_pose: Sequence[float], height_m: float, offset: Sequence[float]) -> np.ndarray:
    """x_d = x_2 x_d^2 (eq. 6.3): the bin marker's pose (x, y, yaw) at ``height_m`` times the
    scene's offset (x, y, z, yaw, pitch, roll), a unit dual quaternion."""
    marker = planar_pose(*bin_pose, height_m)
    return dq.normalize(dq.mul(marker, offset_pose(*offset)))


def scenario(name: str, robot: MobileManipulator, seed: int | None = None) -> SimScenario:
    """The set-up of experiment ``name`` (one of ``NAMES``); a ``seed`` draws a variant."""
    if name not in NAMES:
        raise ValueError(f"no experiment {name!r}; choose one of {', '.join(NAMES)}")
    if robot.name != DECLARED_FOR:
        return derived(name, robot, seed)
    if name == "table":
        return _table(robot, seed)
    x, y, yaw = planar_of(robot.fkm(REACH_GOAL))
    obstacles: tuple[Circle, ...] = ()
    start = HOME.copy()
    if name == "obstacle":
        x, y = x + OBSTACLE_SHIFT[0], y + OBSTACLE_SHIFT[1]
        obstacles = (OBSTACLE,)
    if name in ("anywhere", "blocked"):
        (x, y), yaw = ANYWHERE_BIN, yaw + np.pi
        start[:3] = ANYWHERE_START if name == "anywhere" else BLOCKED_START
        obstacles = (ANYWHERE_OBSTACLE if name == "anywhere" else BLOCKED_OBSTACLE,)
    start, bin_pose = _drawn(start, np.array([x, y, yaw]), seed, BIN_RANGE)
    task = "position" if name == "position" else "pose"
    return SimScenario(name, task, tuple(start.tolist()), tuple(bin_pose.tolist()), obstacles)


def _table(robot: MobileManipulator, seed: int | None) -> SimScenario:
    """'table': the bin marker on the table top under TABLE_GOAL's gripper, x_d^2 the gripper's
    pose seen from it (eq. 6.3 backwards)."""
    goal = robot.fkm(TABLE_GOAL)
    height = TABLE.offset
    x, y, yaw = planar_of(goal)
    offset = offset_of(dq.mul(dq.conj(planar_pose(x, y, yaw, height)), goal))
    start, bin_pose = _drawn(TABLE_START.copy(), np.array([x, y, yaw]), seed, TABLE_BIN_RANGE)
    return SimScenario(
        "table",
        "pose",
        tuple(start.tolist()),
        tuple(bin_pose.tolist()),
        (),
        (TABLE,),
        height,
        tuple(round(v, 9) for v in offset),
    )


def _drawn(
    start: np.ndarray, bin_pose: np.ndarray, seed: int | None, bin_range: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The start and the bin, each moved by a draw of ``seed`` within ``START_RANGE`` and
    ``bin_range`` (as they are without a seed)."""
    if seed is None:
        return start, bin_pose
    rng = np.random.default_rng(seed)
    moved = start + rng.uniform(-START_RANGE, START_RANGE)  # the start's draw first
    return moved, bin_pose + rng.uniform(-bin_range, bin_range)


def derived(name: str, robot: MobileManipulator, seed: int | None = None) -> SimScenario:
    """Set-up ``name`` (one of ``DERIVED``) for a robot other than ``DECLARED_FOR``: from its
    start, the pose of its gripper at its goal configuration (the module docstring); a seed
    draws both configurations (``DRAW``). ``ValueError`` naming what it can choose."""
    mobile = robot.base.kind != "fixed"
    fits = mobile and _obstacle_way_m(robot) <= OBSTACLE_WAY_MAX_M
    choices = DERIVED if fits else DERIVED[:2]
    if name not in choices:
        raise ValueError(
            f"the {name!r} set-up is {DECLARED_FOR}'s; for {robot.name} choose {', '.join(choices)}"
        )
    start = _bent(robot, START_BEND, 1.0)
    goal_q = _ahead(robot, _bent(robot, GOAL_BEND, -1.0), AHEAD if mobile else start[:3])
    if seed is not None:
        rng = np.random.default_rng(seed)
        for q in (start, goal_q):
            q += rng.uniform(-1.0, 1.0, robot.dof) * _draw_range(robot, mobile)
            np.clip(q, *_inside(robot), out=q)
    pose = robot.fkm(goal_q)
    x, y, yaw = planar_of(pose)
    obstacles: tuple[Circle, ...] = ()
    if name == "obstacle":  # the bin past an obstacle on the way, as Little John's
        shift, obstacle = _obstacle_way(robot, goal_q[:2])
        pose = dq.normalize(dq.mul(planar_pose(*shift, 0.0, 0.0), pose))
        x, y, yaw = planar_of(pose)
        obstacles = (obstacle,)
    offset = offset_of(dq.mul(dq.conj(planar_pose(x, y, yaw, 0.0)), pose))
    task = "position" if name == "position" else "pose"
    return SimScenario(
        name,
        task,
        tuple(float(v) for v in start),
        (x, y, yaw),
        obstacles,
        goal_height=0.0,
        goal_offset=tuple(round(v, 9) for v in offset),
    )


def _obstacle_way(robot: MobileManipulator, base_xy: np.ndarray) -> tuple[np.ndarray, Circle]:
    """'obstacle''s shift of the goal from the base at ``base_xy`` (``OBSTACLE_SHIFT``'s
    direction), and its obstacle (``OBSTACLE``'s size) half way from the start to the shifted
    base: Little John's own, scaled up for a larger body so that neither end touches it."""
    way = base_xy + np.array(OBSTACLE_SHIFT)
    way = way * max(1.0, _obstacle_way_m(robot) / float(np.linalg.norm(way)))
    middle = 0.5 * way
    return way - base_xy, Circle(float(middle[0]), float(middle[1]), OBSTACLE.radius)


def _obstacle_way_m(robot: MobileManipulator) -> float:
    """The least way from the start to the goal's base past the obstacle half way, m."""
    return 2.0 * (robot.base.body_radius + OBSTACLE.radius + OBSTACLE_MARGIN_M)


def _inside(robot: MobileManipulator) -> tuple[np.ndarray, np.ndarray]:
    """The bounds ``LIMIT_SHARE`` of each arm joint's range about its middle (the base's
    unbounded)."""
    low, high = robot.q_min.copy(), robot.q_max.copy()
    middle, half = 0.5 * (low[3:] + high[3:]), 0.5 * LIMIT_SHARE * (high[3:] - low[3:])
    low[3:], high[3:] = middle - half, middle + half
    return low, high


def _bent(robot: MobileManipulator, bend: float, sign: float) -> np.ndarray:
    """A configuration at the origin, each arm joint ``bend`` from the middle of its range in
    alternating directions (starting with ``sign``), inside ``_inside``."""
    low, high = _inside(robot)
    q = np.zeros(robot.dof)
    for i, kind in enumerate(robot.joint_types):
        j = 3 + i
        middle, span = 0.5 * (low[j] + high[j]), high[j] - low[j]
        step = bend * span if kind == "prismatic" else bend
        q[j] = np.clip(middle + sign * (-1.0) ** i * step, low[j], high[j])
    return q


TURNS = (0.0, 0.5 * np.pi, -0.5 * np.pi, np.pi)
"""The first joint's turns from a derived goal's bend that ``_ahead`` tries."""


def _ahead(robot: MobileManipulator, q: np.ndarray, base: Sequence[float]) -> np.ndarray:
    """``q`` on ``base`` with its first arm joint turned (``TURNS``, inside ``_inside``) so
    that the gripper lies most ahead of the base and least aside (x - |y| in the base's
    frame): where the ceiling camera sees the bin, as Little John's."""
    low, high = _inside(robot)
    candidates = []
    for turn in TURNS:
        turned = q.copy()
        turned[:3] = 0.0
        turned[3] = np.clip(q[3] + turn, low[3], high[3])
        x, y, _ = planar_of(robot.fkm(turned))
        candidates.append((x - abs(y), turn, turned))
    _, _, best = max(candidates, key=lambda c: (c[0], -abs(c[1])))
    best[:3] = base
    return best


def _draw_range(robot: MobileManipulator, mobile: bool) -> np.ndarray:
    """How far a seed moves each coordinate of a derived configuration (``DRAW``)."""
    spans = robot.q_max[3:] - robot.q_min[3:]
    arm = [
        DRAW * s if k == "prismatic" else DRAW
        for k, s in zip(robot.joint_types, spans, strict=True)
    ]
    return np.concatenate((START_RANGE[:3] if mobile else np.zeros(3), arm))
