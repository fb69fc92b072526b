"""The conservative obstacle bound (wbc/laws/constraints/obstacle_conservative.py; 5.19)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.wbc.laws.constraints.constraint_steps import (
    ROBOT,
    base_at,
    context,
)
from wbc.geometry.obstacles import Circle
from wbc.laws.constraints.base import VelocityBounds
from wbc.laws.constraints.obstacle_conservative import ConservativeObstacle


def test_conservative_obstacle_is_unbounded_without_obstacles() -> None:
    bounds = ConservativeObstacle().rows(context(base_at(1.0, 2.0)))
    assert isinstance(bounds, VelocityBounds)
    assert np.all(bounds.lower == -np.inf) and np.all(bounds.upper == np.inf)


@pytest.mark.parametrize("gain", [0.5, 1.0, 3.0])
def test_conservative_obstacle_bound_shrinks_to_zero_at_the_disc(gain: float) -> None:
    constraint = ConservativeObstacle(gain=gain, margin=0.05)
    obstacle = Circle(2.0, 0.0, 0.3)
    border = 2.0 - (0.3 + ROBOT.base.body_radius + 0.05)
    previous = np.inf
    for x in (border - 1.0, border - 0.5, border - 0.1, border - 0.01):
        bounds = constraint.rows(context(base_at(x, 0.0), obstacles=(obstacle,)))
        expected = gain * (border - x)
        np.testing.assert_allclose(bounds.upper[:2], expected, rtol=1e-12)
        np.testing.assert_allclose(bounds.lower[:2], -expected, rtol=1e-12)
        assert np.all(bounds.upper[2:] == np.inf) and np.all(bounds.lower[2:] == -np.inf)
        assert expected < previous
        previous = expected
    at_border = constraint.rows(context(base_at(border, 0.0), obstacles=(obstacle,)))
    np.testing.assert_allclose(at_border.upper[:2], [0.0, 0.0], rtol=0, atol=1e-12)
    for x in (border + 0.1, 2.0):
        bounds = constraint.rows(context(base_at(x, 0.0), obstacles=(obstacle,)))
        np.testing.assert_array_equal(bounds.upper[:2], [0.0, 0.0])
        np.testing.assert_array_equal(bounds.lower[:2], [0.0, 0.0])


def test_conservative_obstacle_takes_the_nearest_obstacle() -> None:
    near, far = Circle(1.0, 0.0, 0.2), Circle(0.0, -3.0, 0.2)
    bounds = ConservativeObstacle(gain=1.0, margin=0.0).rows(
        context(base_at(0.0, 0.0), obstacles=(far, near))
    )
    expected = 1.0 - 0.2 - ROBOT.base.body_radius
    np.testing.assert_allclose(bounds.upper[:2], expected, rtol=1e-12)


@pytest.mark.parametrize(("gain", "margin"), [(0.0, 0.05), (-1.0, 0.05), (1.0, -0.01)])
def test_conservative_obstacle_rejects_bad_parameters(gain: float, margin: float) -> None:
    with pytest.raises(ValueError):
        ConservativeObstacle(gain=gain, margin=margin)
