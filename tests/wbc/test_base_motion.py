"""From u_b to the differential-drive base (wbc/base_motion.py): unicycle and wheel speeds."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbc.base_motion import unicycle, wheel_speeds
from wbc.robot import BaseDescription

BASE = BaseDescription(
    height=0.170,
    body_radius=0.165,
    wheel_base=0.235,
    wheel_radius=0.036,
    wheel_speed_max=0.5,
    velocity_max=np.array([0.2, 0.2, 1.5]),
)
HALF_TRACK = 0.5 * BASE.wheel_base
NO_DEADLINE = settings(deadline=None)
speeds = st.floats(-3.0, 3.0)
angles = st.floats(-math.pi, math.pi)


@NO_DEADLINE
@given(st.floats(-1.0, 1.0), speeds, angles)
def test_unicycle_recovers_forward_speed_and_turn_rate(v: float, omega: float, phi: float) -> None:
    """u_b = (v cos phi, v sin phi, omega) obeys 5.11 and maps back to (v, omega)."""
    forward, angular = unicycle(v * math.cos(phi), v * math.sin(phi), omega, phi)
    assert forward == pytest.approx(v, abs=1e-12)
    assert angular == omega


def test_unicycle_projects_sideways_motion_away() -> None:
    assert unicycle(0.0, 0.3, 0.0, 0.0) == pytest.approx((0.0, 0.0), abs=1e-15)
    assert unicycle(0.3, 0.0, 0.0, math.pi)[0] == pytest.approx(-0.3)
    assert unicycle(0.3, 0.4, 0.0, math.pi / 2)[0] == pytest.approx(0.4)


def test_straight_motion_drives_both_wheels_alike() -> None:
    result = wheel_speeds(0.3, 0.0, BASE)
    assert result.left_wheel == result.right_wheel == 0.3
    assert (result.forward, result.angular, result.scale) == (0.3, 0.0, 1.0)


def test_spin_in_place_drives_the_wheels_opposite() -> None:
    result = wheel_speeds(0.0, 1.0, BASE)
    assert result.right_wheel == pytest.approx(HALF_TRACK)
    assert result.left_wheel == pytest.approx(-HALF_TRACK)
    assert result.scale == 1.0


def test_arc_turning_left_speeds_up_the_right_wheel() -> None:
    """v -+ omega b / 2; the mean of the wheels is v, their difference over b is omega."""
    result = wheel_speeds(0.2, 0.8, BASE)
    assert result.left_wheel == pytest.approx(0.2 - 0.8 * HALF_TRACK)
    assert result.right_wheel == pytest.approx(0.2 + 0.8 * HALF_TRACK)
    assert 0.5 * (result.left_wheel + result.right_wheel) == pytest.approx(result.forward)
    assert (result.right_wheel - result.left_wheel) / BASE.wheel_base == pytest.approx(0.8)


def test_too_fast_arc_is_scaled_by_one_factor() -> None:
    result = wheel_speeds(0.5, 2.0, BASE)
    fastest = 0.5 + 2.0 * HALF_TRACK
    assert result.scale == pytest.approx(0.5 / fastest)
    assert result.right_wheel == pytest.approx(0.5)
    assert result.forward == pytest.approx(0.5 * result.scale)
    assert result.angular == pytest.approx(2.0 * result.scale)


@NO_DEADLINE
@given(speeds, speeds)
def test_no_wheel_exceeds_its_limit_and_curvature_is_kept(v: float, omega: float) -> None:
    result = wheel_speeds(v, omega, BASE)
    limit = BASE.wheel_speed_max
    assert max(abs(result.left_wheel), abs(result.right_wheel)) <= limit * (1.0 + 1e-12)
    assert 0.0 < result.scale <= 1.0
    # One factor on v and omega: the wheel speeds are the unscaled ones times the factor, and
    # the path's curvature omega / v is unchanged.
    assert result.forward == pytest.approx(result.scale * v, abs=1e-15)
    assert result.angular == pytest.approx(result.scale * omega, abs=1e-15)
    assert result.left_wheel == pytest.approx(result.scale * (v - omega * HALF_TRACK), abs=1e-15)
    assert result.right_wheel == pytest.approx(result.scale * (v + omega * HALF_TRACK), abs=1e-15)
    unscaled_fastest = abs(v) + abs(omega) * HALF_TRACK
    if unscaled_fastest <= limit:
        assert result.scale == 1.0
    else:
        assert max(abs(result.left_wheel), abs(result.right_wheel)) == pytest.approx(limit)


@pytest.mark.parametrize(
    ("forward", "angular"), [(math.nan, 0.0), (0.0, math.nan), (math.inf, 0.0), (0.1, -math.inf)]
)
def test_non_finite_base_velocity_raises(forward: float, angular: float) -> None:
    with pytest.raises(ValueError, match="finite"):
        wheel_speeds(forward, angular, BASE)
