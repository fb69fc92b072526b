"""Random pose goals (studies/goal_families.py): each family's goals are reachable
configurations inside its box, drawn from seeds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE
from studies.goal_families import FAMILIES, goals
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
HELD_OUT_SEED = 3
"""A set of goals the secondary terms were not tuned on (they were tuned on seed 1)."""


@pytest.mark.parametrize("family", list(FAMILIES.values()), ids=list(FAMILIES))
def test_goals_are_reachable_configurations_of_their_family(family):
    low, high = family.box(ROBOT)
    for start, goal in goals(family, 50, ROBOT, HELD_OUT_SEED):
        assert start[:3].tolist() == [0.0, 0.0, 0.0]
        assert family.distance[0] <= math.hypot(*goal[:2]) <= family.distance[1]
        assert family.bearing[0] <= math.atan2(goal[1], goal[0]) <= family.bearing[1]
        assert family.heading[0] <= goal[2] <= family.heading[1]
        for arm in (start[3:], goal[3:]):
            assert (low <= arm).all() and (arm <= high).all()
        assert (ROBOT.q_min <= goal).all() and (goal <= ROBOT.q_max).all()


def test_goals_ahead_drawn_another_way_start_the_arm_anywhere_in_its_box():
    """Issue 33's goals: the arm's start spread over its box, not near HOME."""
    for name in ("ahead, any arm start", "ahead, wide arm"):
        low, high = FAMILIES[name].box(ROBOT)
        starts = np.array([start[3:] for start, _ in goals(FAMILIES[name], 200, ROBOT)])
        assert (starts.min(axis=0) < low + 0.1 * (high - low)).all()
        assert (starts.max(axis=0) > high - 0.1 * (high - low)).all()
