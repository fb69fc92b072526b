"""The staging search's inverse kinematics (wbc/planning/whole_body_ik.py): a configuration of
the goal pose inside the search's box, the waist held at 0, or None where there is none."""

from __future__ import annotations

import numpy as np

from tests.wbc.wbc_scenarios import robot
from wbc import dq
from wbc.geometry.scenarios import HOME, REACH_GOAL
from wbc.laws.lp_law import LPParams
from wbc.planning.whole_body_ik import arm_box, free_entries, solve_ik
from wbc.robot import BASE_DOF

MODEL = robot()


def bounds(margin: float) -> tuple[np.ndarray, np.ndarray]:
    """The search's bounds on the free entries: the base free, the arm in its shrunk box."""
    low, high = arm_box(MODEL, LPParams().safety_factor, margin)
    free = np.full(BASE_DOF, np.inf)
    return np.concatenate((-free, low[1:])), np.concatenate((free, high[1:]))


def test_a_configuration_of_the_goal_pose_is_found_inside_the_box_with_the_waist_at_0() -> None:
    goal = MODEL.fkm(REACH_GOAL)
    low, high = bounds(0.05)
    q = solve_ik(MODEL, goal, HOME, (low, high), 1e-6)
    assert q is not None and q[BASE_DOF] == 0.0
    assert np.linalg.norm(MODEL.fkm(q) - dq.nearest_equivalent(goal, MODEL.fkm(q))) < 1e-6
    free = free_entries(MODEL.dof)
    assert free == [*range(BASE_DOF), *range(BASE_DOF + 1, MODEL.dof)]
    assert np.all(q[free] >= low - 1e-12) and np.all(q[free] <= high + 1e-12)


def test_a_pose_no_configuration_reaches_gives_none() -> None:
    goal = MODEL.fkm(REACH_GOAL)
    far_up = dq.pose(dq.rotation(goal), dq.translation(goal)[1:] + [0.0, 0.0, 5.0])
    assert solve_ik(MODEL, far_up, HOME, bounds(0.05), 1e-6) is None
