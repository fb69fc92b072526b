"""Where the arm driver aims each AX-18A servo: ahead of the joint in the direction of motion
(``lookahead_s`` of its speed, at least ``min_step`` units), at the commanded speed; a joint too
slow for a Moving Speed holds where it stopped; every goal inside the joint's limits.

AX-18A units: 1024 per 300 degrees (195.57 per rad), 512 at the centre; Moving Speed 0.111 rpm
(0.011624 rad/s) per unit. The figures below are worked out from those."""

from __future__ import annotations

import numpy as np
import pytest

from components.arm_goals import ArmGoals
from components.servo_bus import HOLD_SPEED, AXBus
from wbc.servo_map import ServoMap

SERVOS = ServoMap(ids=(1, 2), offsets=(0.0, 0.1), directions=(1, -1))
"""Joint 0 turns as its servo; joint 1's servo is turned 0.1 rad and the other way."""
LOW, HIGH = np.array([-1.0, -1.0]), np.array([1.0, 0.5])
PARAMS = {"lookahead_s": 0.25, "min_step": 8}


@pytest.fixture
def goals() -> ArmGoals:
    return ArmGoals(SERVOS, AXBus("/dev/null"), LOW, HIGH, PARAMS)


def test_the_goals_inside_the_limits_in_units(goals: ArmGoals) -> None:
    # joint 0: 512 -+ 195.57 -> 316.4 .. 707.6; joint 1: servo angles 0.1 - q, -0.4 .. 1.1 rad
    assert goals.goal_low == [317, 434]
    assert goals.goal_high == [707, 727]


def test_a_moving_joint_aims_a_lookahead_ahead_at_its_speed(goals: ArmGoals) -> None:
    assert goals.ahead(0, 1.0, 0.0) == (561, 86)  # 0.25 rad ahead: 512 + 48.9
    assert goals.ahead(0, -1.0, 0.9) == (639, 86)  # to 0.65 rad: 512 + 127.1
    assert goals.ahead(1, 1.0, 0.0) == (483, 86)  # servo to 0.1 - 0.25 rad: 512 - 29.3


def test_a_slow_joint_aims_at_least_min_step_ahead(goals: ArmGoals) -> None:
    assert goals.ahead(0, 0.05, 0.0) == (520, 4)  # 0.0125 rad is 2.4 units: 8 instead


def test_a_goal_past_a_limit_is_the_limit(goals: ArmGoals) -> None:
    assert goals.ahead(0, 1.0, 0.95) == (707, 86)  # 1.2 rad would be 746.7
    assert goals.ahead(1, 1.0, 0.5) == (434, 86)  # servo to -0.65 rad would be 384.9


def test_a_stopped_joint_holds_where_it_stopped_until_it_moves(goals: ArmGoals) -> None:
    assert goals.ahead(0, 0.001, 0.2) == (551, HOLD_SPEED)  # speed rounds to 0: 512 + 39.1
    assert goals.ahead(0, 0.0, 0.3) == (551, HOLD_SPEED)  # it does not creep to the new reading
    goals.ahead(0, 1.0, 0.3)
    assert goals.ahead(0, 0.0, 0.3) == (571, HOLD_SPEED)  # stopped again: 512 + 58.7


def test_check_refuses_a_goal_outside_the_limits_or_a_speed_the_bus_cannot_write(
    goals: ArmGoals,
) -> None:
    goals.check((1, 2), (317, 727), (1, 1023))
    with pytest.raises(ValueError, match="servo 1: goal 708"):
        goals.check((1, 2), (708, 500), (1, 1))
    with pytest.raises(ValueError, match="servo 2: goal 500 or speed 0"):
        goals.check((1, 2), (500, 500), (1, 0))
    with pytest.raises(ValueError, match="speed 1024"):
        goals.check((1, 2), (500, 500), (1024, 1))
