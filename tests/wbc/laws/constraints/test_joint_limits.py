"""The joint-limit bounds (wbc/laws/constraints/joint_limits.py; 5.13-5.18)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.wbc.laws.constraints.constraint_steps import (
    NO_DEADLINE,
    ROBOT,
    context,
)
from wbc.laws.constraints.base import VelocityBounds
from wbc.laws.constraints.joint_limits import JointLimits


def arm_inside(safety_factor: float) -> st.SearchStrategy[np.ndarray]:
    """Arm configurations inside the shrunk box b_l [q-, q+]."""
    low, high = safety_factor * ROBOT.q_min[3:], safety_factor * ROBOT.q_max[3:]
    return st.tuples(*[st.floats(lo, hi) for lo, hi in zip(low, high, strict=True)]).map(np.array)


@NO_DEADLINE
@given(
    st.floats(0.1, 10.0),
    st.floats(0.5, 1.0),
    st.data(),
    st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)),
)
def test_joint_limit_bounds_are_equation_5_15(
    gain: float, safety_factor: float, data: st.DataObject, base: tuple[float, float, float]
) -> None:
    arm = data.draw(arm_inside(safety_factor))
    q = np.concatenate((base, arm))
    bounds = JointLimits(gain, safety_factor).rows(context(q))
    assert isinstance(bounds, VelocityBounds)
    speed = ROBOT.velocity_max
    lower = np.maximum(-speed[3:], gain * (safety_factor * ROBOT.q_min[3:] - arm))
    upper = np.minimum(speed[3:], gain * (safety_factor * ROBOT.q_max[3:] - arm))
    np.testing.assert_allclose(bounds.lower[3:], lower, rtol=0, atol=1e-12)
    np.testing.assert_allclose(bounds.upper[3:], upper, rtol=0, atol=1e-12)
    # The base has no position limits: only its velocity bounds remain, wherever it is.
    np.testing.assert_array_equal(bounds.lower[:3], -speed[:3])
    np.testing.assert_array_equal(bounds.upper[:3], speed[:3])


def test_joint_limit_bound_shrinks_near_the_limit() -> None:
    """k (b_l q+ - q) takes over from the speed limit as the joint nears b_l q+."""
    q = np.zeros(ROBOT.dof)
    q[4] = 0.9 * ROBOT.q_max[4] - 0.1
    bounds = JointLimits(gain=2.0, safety_factor=0.9).rows(context(q))
    assert bounds.upper[4] == pytest.approx(0.2)
    assert bounds.lower[4] == -ROBOT.velocity_max[4]
    q[4] = 0.9 * ROBOT.q_max[4]
    assert JointLimits(gain=2.0, safety_factor=0.9).rows(context(q)).upper[4] == pytest.approx(0)


@NO_DEADLINE
@given(st.integers(3, 7), st.floats(1e-6, 3.0), st.floats(0.1, 10.0), st.floats(0.5, 1.0))
def test_joint_beyond_the_upper_margin_must_move_back(
    joint: int, overshoot: float, gain: float, safety_factor: float
) -> None:
    q = np.zeros(ROBOT.dof)
    q[joint] = safety_factor * ROBOT.q_max[joint] + overshoot
    bounds = JointLimits(gain, safety_factor).rows(context(q))
    speed = ROBOT.velocity_max[joint]
    assert bounds.upper[joint] <= 0.0
    assert -speed <= bounds.lower[joint] <= bounds.upper[joint]


@NO_DEADLINE
@given(st.integers(3, 7), st.floats(1e-6, 3.0), st.floats(0.1, 10.0), st.floats(0.5, 1.0))
def test_joint_beyond_the_lower_margin_must_move_back(
    joint: int, overshoot: float, gain: float, safety_factor: float
) -> None:
    q = np.zeros(ROBOT.dof)
    q[joint] = safety_factor * ROBOT.q_min[joint] - overshoot
    bounds = JointLimits(gain, safety_factor).rows(context(q))
    speed = ROBOT.velocity_max[joint]
    assert bounds.lower[joint] >= 0.0
    assert bounds.lower[joint] <= bounds.upper[joint] <= speed


@NO_DEADLINE
@given(st.lists(st.floats(-10.0, 10.0), min_size=8, max_size=8), st.floats(0.1, 10.0))
def test_joint_limit_bounds_are_ordered_and_within_speed(q: list[float], gain: float) -> None:
    bounds = JointLimits(gain, 0.9).rows(context(np.array(q)))
    speed = ROBOT.velocity_max
    # Declared ordered, so the LP skips its test of lower > upper: it must hold.
    assert bounds.ordered and np.all(bounds.lower <= bounds.upper)
    assert np.all(-speed <= bounds.lower) and np.all(bounds.upper <= speed)
    assert np.all(np.isfinite(bounds.lower)) and np.all(np.isfinite(bounds.upper))


@pytest.mark.parametrize(("gain", "safety_factor"), [(0.0, 0.9), (-1.0, 0.9), (1, 0), (1, 1.1)])
def test_joint_limits_reject_bad_parameters(gain: float, safety_factor: float) -> None:
    with pytest.raises(ValueError):
        JointLimits(gain, safety_factor)
