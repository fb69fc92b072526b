"""The hyper-redundant study's goals, reachable by construction, and the bound the LP keeps at
every step (its study, studies/files/redundancy.yaml, runs in tests/studies/study/)."""

from __future__ import annotations

import math

import numpy as np

from profiles.deploy_files import DEPLOY, zoo
from studies.redundancy import BASE_MOVE, TASKS, arm_box, draw, engaged_count, task_of
from wbc.geometry.scenarios import DT
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.robot import BASE_DOF, MobileManipulator

ROBOTS = DEPLOY / "robots"
LITTLE_JOHN, SNAKE, SEVEN = (
    ROBOTS / f"{name}.yaml" for name in ("little_john", "snake12", "arm7_differential")
)


def test_the_zoo_is_every_description_and_the_study_runs_them_all() -> None:
    assert {LITTLE_JOHN, SNAKE, SEVEN} <= set(zoo())


def test_goals_are_configurations_inside_every_limit_drawn_from_a_fixed_seed() -> None:
    """Start and goal arms in the LP's joint box and the limits, every frame above the floor,
    the goal's base moved as the bench's goals ahead; the same seed, the same goals. Where a
    range does not straddle zero (the Panda's q4) the box lies inside the limit too."""
    robot = MobileManipulator.from_yaml(SEVEN)
    pairs = draw(robot, 5)
    low, high = arm_box(robot)
    assert robot.q_min[BASE_DOF + 3] < low[3] < high[3] < robot.q_max[BASE_DOF + 3] < 0.0
    for (start, goal), (again, _) in zip(pairs, draw(robot, 5), strict=True):
        assert np.array_equal(start, again)
        for q in (start, goal):
            assert np.all(low <= q[BASE_DOF:]) and np.all(q[BASE_DOF:] <= high)
            assert robot.link_points(q)[:, 2].min() > 0.0
        assert np.array_equal(start[:BASE_DOF], np.zeros(3))
        assert BASE_MOVE.distance[0] <= math.hypot(*goal[:2]) <= BASE_MOVE.distance[1]


def test_the_lp_of_5_29_uses_at_most_the_tasks_dof_plus_the_constraints_engaged() -> None:
    """On the 15-DOF snake, every step of 5.29 (the default LP without its base target, whose
    residual rows are rows of the program too): nonzero entries <= 6 + engaged."""
    robot = MobileManipulator.from_yaml(SNAKE)
    start, goal = draw(robot, 1)[0]
    law, task = LPLaw(robot, LPParams(base_target=0.0)), task_of(robot, goal, "pose")
    q, counts = start, []
    for _ in range(40):
        out = law.step(q, task, DT)
        assert out.nonzero <= TASKS["pose"] + engaged_count(out)
        counts.append(out.nonzero)
        q = q + out.u * DT
    assert max(counts) < robot.dof
