"""What `parsimony reproduce` measures on a kinematic run (studies/reproduce/measures.py): the
entries counted under both rules, the faster wheel's speed, the residual of J u = -eta e."""

from __future__ import annotations

import math

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE
from studies.reproduce.measures import both_rules, least_residual, median, wheel_speed
from wbc.geometry.scenarios import HOME, REACH_GOAL
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)


def test_x_and_y_rates_count_as_one_entry_under_the_second_rule() -> None:
    masks = [0b11, 0b111, 0b101]  # x' y', x' y' phi', x' phi'
    assert both_rules(masks) == [2.0, 2.0]
    assert both_rules([0b11]) == [2.0, 1.0]
    assert math.isnan(median([]))


def test_the_faster_wheel_carries_the_forward_speed_and_half_the_turn() -> None:
    u = np.array([0.3, 0.4, 2.0, 0, 0, 0, 0, 0])
    forward = 0.3 * math.cos(0.5) + 0.4 * math.sin(0.5)
    expected = abs(forward) + 2.0 * ROBOT.base.wheel_base / 2
    assert wheel_speed(u, 0.5, ROBOT) == pytest.approx(expected)


def test_the_unicycles_least_residual_is_never_below_the_whole_bodys() -> None:
    """Under 5.11 u = N v spans part of what u spans: J N reaches less of e than J does."""
    task = PoseTask(ROBOT.fkm(REACH_GOAL))
    free = least_residual(ROBOT, task, HOME, nonholonomic=False)
    unicycle = least_residual(ROBOT, task, HOME, nonholonomic=True)
    assert 0.0 <= free <= unicycle + 1e-12 <= 1.0 + 1e-12
