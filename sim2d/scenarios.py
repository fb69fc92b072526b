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
