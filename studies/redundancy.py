"""The hyper-redundant question (issue 35): how many entries of u each law uses, against the
robot's DOF and the task's, over every robot of the zoo.

The dissertation (6.2.2) saw on one robot that "more redundancy implies a smaller number of DOF
used", and its future work orients the parsimonious law "mainly to hyper-redundant systems".
At a vertex of 5.29 every nonzero entry of u is a basic column, so the LP's count is at most
the rank of its tight rows: the task's DOF (6 for a pose, 3 for a position) plus the
constraints engaged (the nonholonomic equality, the 1-norm bound 5.10, the entries at a
velocity bound), whatever the robot's DOF; the pseudoinverse moves every entry.

Goals are reachable by construction: from SEED, a start and a goal configuration with the arm
anywhere in the box the LP keeps it in (``arm_box``) and every frame above the floor, the goal's
base moved as the bench's 'ahead' goals move it (``studies.goal_families``; not at all on a
fixed base); the goal is the goal configuration's end-effector pose, or its position. Each law
runs in kinematic closed loop (``wbc.laws.kinematic_run.integrate``) for at most TIME_LIMIT_S.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from studies.goal_families import FAMILIES
from studies.goal_sets import LIMIT_TOLERANCE, MOVING_ERROR, TOLERANCE
from wbc import dq
from wbc.geometry.scenarios import DT
from wbc.laws.law_output import ZERO_THRESHOLD, Law, LawOutput
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.pinv_law import PinvParams, PseudoinverseLaw
from wbc.laws.qp_law import QPLaw, QPParams
from wbc.robot import BASE_DOF, MobileManipulator
from wbc.task import PoseTask, PositionTask, Task

Array = np.ndarray

SEED = 35
"""The study's goals (issue 35)."""
GOALS = 100
"""Goals per robot (each run as a pose goal and as a position goal)."""
BASE_MOVE = FAMILIES["ahead"]
"""How far the goal's base lies from the start's: the dissertation's kind of goal."""
FLOOR = 0.0
"""Every frame origin of a start or goal configuration lies above this height (m)."""
TIME_LIMIT_S = 20.0
"""A run's time limit: a goal not reached by then counts as missed (the bench gives 60 s; most
goals the laws reach here, they reach in 10 to 15 s)."""


def mobility(robot: MobileManipulator) -> int:
    """How many velocities the robot can set independently: the arm's joints and the base's
    forward speed and yaw (differential), its three velocities (omnidirectional) or none."""
    extra = {"differential": 2, "omnidirectional": 3, "fixed": 0}[robot.base.kind]
    return robot.arm_dof + extra


def _lp_gains(robot: MobileManipulator) -> dict[str, bool]:
    return {"nonholonomic": robot.base.kind == "differential"}


LAWS: dict[str, Callable[[MobileManipulator], Law]] = {
    "lp": lambda robot: LPLaw(robot, LPParams(**_lp_gains(robot))),
    "qp": lambda robot: QPLaw(robot, QPParams(**_lp_gains(robot))),
    "pinv": lambda robot: PseudoinverseLaw(robot, PinvParams(**_lp_gains(robot))),
}
"""The default LP, the QP of the same rows and terms, and the classic pseudoinverse (5.3): on a
differential base, the pseudoinverse of the velocities 5.11 allows (``PinvParams``); 5.12 only
on a differential base."""
TASKS = {"pose": PoseTask.dof, "position": PositionTask.dof}
"""The goal families, by the task's DOF."""


def arm_box(robot: MobileManipulator) -> tuple[Array, Array]:
    """The arm's part of the LP's joint box b_l [q-, q+] (``MobileManipulator.joint_box``)."""
    low, high = robot.joint_box(LPParams().safety_factor)
    return low[BASE_DOF:], high[BASE_DOF:]


def above_floor(robot: MobileManipulator, q: Array) -> bool:
    """Every frame origin of ``q`` above FLOOR."""
    return bool(robot.link_points(q)[:, 2].min() > FLOOR)


def draw(robot: MobileManipulator, count: int, seed: int = SEED) -> list[tuple[Array, Array]]:
    """``count`` (start, goal configuration) pairs: the start base at the origin facing x."""
    rng = np.random.default_rng(seed)
    low, high = arm_box(robot)
    fixed = robot.base.kind == "fixed"
    pairs: list[tuple[Array, Array]] = []
    while len(pairs) < count:
        start = np.concatenate((np.zeros(BASE_DOF), rng.uniform(low, high)))
        distance, bearing = rng.uniform(*BASE_MOVE.distance), rng.uniform(*BASE_MOVE.bearing)
        heading = rng.uniform(*BASE_MOVE.heading)
        base = [0.0] * 3 if fixed else [distance * math.cos(bearing), distance * math.sin(bearing)]
        goal = np.concatenate((base[:2] + [0.0 if fixed else heading], rng.uniform(low, high)))
        if above_floor(robot, start) and above_floor(robot, goal):
            pairs.append((start, goal))
    return pairs


def task_of(robot: MobileManipulator, goal: Array, family: str) -> Task:
    """The pose of ``goal``'s end effector, or its position."""
    pose = robot.fkm(goal)
    return PoseTask(pose) if family == "pose" else PositionTask(dq.translation(pose)[1:])


@dataclass(frozen=True)
class Outcome:
    """One closed-loop run: reached inside every limit, and at each step the nonzero entries
    of u, the constraints engaged (``LawOutput.active_constraints``) and ||e||."""

    reached: bool
    within_limits: bool
    seconds: float
    nonzero: Array
    engaged: Array
    error: Array

    @property
    def reached_within_limits(self) -> bool:
        return self.reached and self.within_limits


def engaged_count(out: LawOutput) -> int:
    """The constraints engaged at a step that can hold an entry of u: every active row
    (5.12, 5.10, an obstacle's) and every entry at its velocity bound (``name[i]``) that is
    nonzero (an entry held at 0 by its bound adds no column to the vertex)."""
    count = 0
    for name in out.active_constraints:
        entry = re.fullmatch(r".*\[(\d+)\]", name)
        count += entry is None or abs(out.u[int(entry[1])]) > ZERO_THRESHOLD
    return count


def run_one(
    law: Law, robot: MobileManipulator, task: str, start: Array, goal: Array, time_limit_s: float
) -> Outcome:
    """``law`` from ``start`` to the pose (``task`` pose) or the position of ``goal``'s end
    effector, for at most ``time_limit_s``."""
    target = task_of(robot, goal, task)
    q = np.array(start, dtype=float)
    nonzero, engaged, error = [], [], []
    joint_over = speed_over = 0.0
    reached = False
    for _ in range(round(time_limit_s / DT)):
        out = law.step(q, target, DT)
        nonzero.append(out.nonzero)
        engaged.append(engaged_count(out))
        error.append(out.error_norm)
        if out.error_norm < TOLERANCE:
            reached = True
            break
        speed_over = max(speed_over, float((np.abs(out.u) - robot.velocity_max).max()))
        q = q + out.u * DT
        joint_over = max(joint_over, float(np.maximum(q - robot.q_max, robot.q_min - q).max()))
    return Outcome(
        reached,
        max(joint_over, speed_over) <= LIMIT_TOLERANCE,
        len(error) * DT,
        np.array(nonzero, np.int16),
        np.array(engaged, np.int16),
        np.array(error),
    )


def _median(values: Iterable[float]) -> float:
    values = list(values)
    return float(np.median(values)) if values else math.nan


def summary(outcomes: list[Outcome], task_dof: int) -> dict[str, float]:
    """The share reached (inside every limit, and at all), the median time to reach, and the
    medians of nonzero entries and engaged constraints while moving (||e|| > MOVING_ERROR) and
    near the goal (the other steps); ``within_bound``, the share of steps whose nonzero count is
    at most the task's DOF plus the constraints engaged."""
    count = max(len(outcomes), 1)
    steps = {"moving": [], "near": []}
    for outcome in outcomes:
        moving = outcome.error > MOVING_ERROR
        steps["moving"].append((outcome.nonzero[moving], outcome.engaged[moving]))
        steps["near"].append((outcome.nonzero[~moving], outcome.engaged[~moving]))
    row: dict[str, float] = {
        "reached_within_limits": sum(o.reached_within_limits for o in outcomes) / count,
        "reached": sum(o.reached for o in outcomes) / count,
        "median_time_s": _median(o.seconds for o in outcomes if o.reached),
    }
    every_nonzero, every_bound = [], []
    for part, pairs in steps.items():
        nonzero = np.concatenate([p[0] for p in pairs]) if pairs else np.zeros(0)
        engaged = np.concatenate([p[1] for p in pairs]) if pairs else np.zeros(0)
        row[f"nonzero_{part}"] = _median(nonzero)
        row[f"engaged_{part}"] = _median(engaged)
        every_nonzero.append(nonzero)
        every_bound.append(task_dof + engaged)
    nonzero, bound = np.concatenate(every_nonzero), np.concatenate(every_bound)
    row["within_bound"] = float(np.mean(nonzero <= bound)) if nonzero.size else math.nan
    return row


def entries(robot: MobileManipulator) -> int:
    """The entries of u a robot can move: all of them, but the base's three on a fixed base (a
    differential base's x' and y' are two entries of one velocity)."""
    return robot.arm_dof if robot.base.kind == "fixed" else robot.dof
