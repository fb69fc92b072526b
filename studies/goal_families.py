"""Random pose goals: families of goal configurations, each declared once, drawn from seeds.

A goal is the end-effector pose of a goal configuration: the base placed some distance and
bearing from the start, at some heading, with the arm in a box of joint angles; so every goal
is reachable. ``studies.goal_sets`` runs the laws on them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.geometry.scenarios import ARM_BOX, HOME
from wbc.laws.lp_law import LPParams
from wbc.robot import BASE_DOF, MobileManipulator

Array = np.ndarray

START_SPREAD = 0.3
"""A start arm near HOME: each joint moved by up to this much (rad), clipped to the box."""
GOAL_SEED = 2
"""The bench's goals. The secondary objective terms were tuned on seed 1, so it is not used."""


WIDE_ARM_BOX = (np.array([-0.8, -1.2, -1.2, -0.8, -0.8]), np.array([0.8, 0.3, 0.3, 0.8, 0.8]))
"""A wider moderate box of arm angles (rad) inside the 0.9-scaled joint limits: ARM_BOX with
the waist and both wrist joints to +-0.8, the shoulder and the elbow bent back to -1.2 (the
gripper above the base)."""
for _bound in WIDE_ARM_BOX:
    _bound.flags.writeable = False


@dataclass(frozen=True)
class GoalFamily:
    """Goal base at distance and bearing from the start base (facing x), at a heading; the
    arm's goal in ``arm``: a box of joint angles (low, high), or a factor b of the joint
    limits, b [q-, q+] (the LP's joint box for b = its safety factor). The arm's start is
    HOME's, each joint moved by up to ``start_spread`` (clipped to the box), or, with None,
    anywhere in the box."""

    name: str
    distance: tuple[float, float]
    bearing: tuple[float, float]
    heading: tuple[float, float]
    arm: tuple[Array, Array] | float = ARM_BOX
    start_spread: float | None = START_SPREAD

    def box(self, robot: MobileManipulator) -> tuple[Array, Array]:
        """The arm's box (low, high), rad."""
        if isinstance(self.arm, float):
            return self.arm * robot.q_min[BASE_DOF:], self.arm * robot.q_max[BASE_DOF:]
        return self.arm

    def sample(self, rng: np.random.Generator, robot: MobileManipulator) -> tuple[Array, Array]:
        """(start configuration, goal configuration)."""
        low, high = self.box(robot)
        if self.start_spread is None:
            arm_start = rng.uniform(low, high)
        else:
            spread = rng.uniform(-self.start_spread, self.start_spread, 5)
            arm_start = np.clip(HOME[3:] + spread, low, high)
        distance, bearing = rng.uniform(*self.distance), rng.uniform(*self.bearing)
        base = [
            distance * math.cos(bearing),
            distance * math.sin(bearing),
            rng.uniform(*self.heading),
        ]
        goal = np.concatenate((base, rng.uniform(low, high)))
        return np.concatenate((HOME[:3], arm_start)), goal


AHEAD = math.radians(35.0)
FAMILIES = {
    "ahead": GoalFamily("ahead", (0.3, 1.2), (-AHEAD, AHEAD), (-AHEAD, AHEAD)),
    "anywhere": GoalFamily(
        "anywhere",
        (0.0, 1.2),
        (-math.pi, math.pi),
        (-math.pi, math.pi),
        LPParams().safety_factor,
        None,
    ),
    "ahead, any arm start": GoalFamily(
        "ahead, any arm start", (0.3, 1.2), (-AHEAD, AHEAD), (-AHEAD, AHEAD), start_spread=None
    ),
    "ahead, wide arm": GoalFamily(
        "ahead, wide arm", (0.3, 1.2), (-AHEAD, AHEAD), (-AHEAD, AHEAD), WIDE_ARM_BOX, None
    ),
}
"""'ahead': the dissertation's kind (goal base 0.3-1.2 m away, within 35 degrees of straight
ahead, heading within 35 degrees, the arm starting near HOME); 'anywhere': within 1.2 m at any
bearing and heading, the arm's start and goal anywhere in the LP's joint box. The goals ahead
as issue 33 drew them, the arm's start anywhere in the goal's box: 'ahead, any arm start'
(ARM_BOX), 'ahead, wide arm' (WIDE_ARM_BOX)."""


@dataclass(frozen=True)
class ObstacleFamily:
    """Goals of ``goals``, each with one circle of ``radius`` near the straight way from the
    start base to the goal's: its centre a share U(0.2, 0.8) along the way and U(-near, near)
    beside it, pushed further aside (in steps of 1 cm) until the base's body, with the LP's
    margin, clears it at the start and at the goal, and the goal's gripper stands outside it
    by the margin. Every goal is reached by its own configuration, clear of the circle."""

    name: str
    goals: GoalFamily
    radius: float = 0.1
    near: float = 0.2
    margin: float = LPParams().obstacle_margin
    seed: int = 25
    """The bench's goals: held out (the planner was tuned on seeds 1 and 4)."""

    def sample(
        self, rng: np.random.Generator, robot: MobileManipulator
    ) -> tuple[Array, Array, Circle]:
        """(start configuration, goal configuration, the circle)."""
        start, goal = self.goals.sample(rng, robot)
        way = goal[:2] - start[:2]
        length = float(np.hypot(*way))
        along = way / length if length > 1e-9 else np.array([1.0, 0.0])
        aside = np.array([-along[1], along[0]])
        centre = start[:2] + rng.uniform(0.2, 0.8) * way
        offset = rng.uniform(-self.near, self.near)
        side = 1.0 if offset >= 0.0 else -1.0
        gripper = dq.translation(robot.fkm(goal))[1:3]
        body = self.radius + robot.base.body_radius + self.margin
        while not (
            np.hypot(*(centre + offset * aside - start[:2])) >= body
            and np.hypot(*(centre + offset * aside - goal[:2])) >= body
            and np.hypot(*(centre + offset * aside - gripper)) >= self.radius + self.margin
        ):
            offset += side * 0.01
        x, y = centre + offset * aside
        return start, goal, Circle(float(x), float(y), self.radius)


OBSTACLE_FAMILIES = {
    "anywhere, obstacle": ObstacleFamily("anywhere, obstacle", FAMILIES["anywhere"]),
}
"""Goals with an obstacle (issue 25): the 'anywhere' goals, each with a circle of 0.1 m near
the straight way, which the supervised LP must drive round."""


def obstacle_goals(
    family: ObstacleFamily, count: int, robot: MobileManipulator, seed: int | None = None
) -> list[tuple[Array, Array, Circle]]:
    """``count`` goals of ``family`` drawn from ``seed`` (the family's own by default)."""
    rng = np.random.default_rng(family.seed if seed is None else seed)
    return [family.sample(rng, robot) for _ in range(count)]


def goals(
    family: GoalFamily, count: int, robot: MobileManipulator, seed: int = GOAL_SEED
) -> list[tuple[Array, Array]]:
    """``count`` goals of ``family`` drawn from ``seed`` (the bench's by default)."""
    rng = np.random.default_rng(seed)
    return [family.sample(rng, robot) for _ in range(count)]
