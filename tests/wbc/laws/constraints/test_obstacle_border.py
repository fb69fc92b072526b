"""The border obstacle rows (wbc/laws/constraints/obstacle_border.py; 5.21-5.28)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.wbc.laws.constraints.constraint_steps import (
    NO_DEADLINE,
    ROBOT,
    angles,
    base_at,
    context,
    finite,
)
from wbc.geometry.obstacles import Circle
from wbc.laws.constraints.base import LinearRows
from wbc.laws.constraints.obstacle_border import BorderObstacle

OBSTACLE = Circle(1.0, 0.5, 0.25)
GAIN, MARGIN = 2.0, 0.05
EXTENDED_RADIUS = OBSTACLE.radius + ROBOT.base.body_radius + MARGIN
CENTRE = np.array([OBSTACLE.x, OBSTACLE.y])


def border_rows(
    x: float, y: float, goal: tuple[float, float], phi: float = 0.0, lookahead: float = 0.0
) -> LinearRows:
    step = context(base_at(x, y, phi), goal_xy=goal, obstacles=(OBSTACLE,))
    return BorderObstacle(gain=GAIN, margin=MARGIN, lookahead=lookahead).rows(step)


@pytest.mark.parametrize("lookahead", [0.0, 0.1])
def test_border_obstacle_is_off_outside_the_extended_disc(lookahead: float) -> None:
    """f <= 0: the row is all zeros and not engaged, even with the obstacle on the way."""
    x = OBSTACLE.x - EXTENDED_RADIUS - 2.0 * lookahead - 0.01  # p = axle + lookahead along x
    rows = border_rows(x, OBSTACLE.y, (3.0, OBSTACLE.y), lookahead=lookahead)
    assert not rows.engaged
    assert rows.matrix.shape == (1, ROBOT.dof)
    assert not np.any(rows.matrix) and not np.any(rows.lower) and not np.any(rows.upper)


@pytest.mark.parametrize("lookahead", [0.0, 0.1])
def test_border_obstacle_is_off_when_the_obstacle_is_not_towards_the_goal(lookahead: float) -> None:
    """Inside the disc (f > 0) but the goal is nearer to the base than to the obstacle: h <= 0."""
    x, y = OBSTACLE.x - 0.5 * EXTENDED_RADIUS - lookahead, OBSTACLE.y
    rows = border_rows(x, y, (x - 2.0, y), lookahead=lookahead)
    assert not rows.engaged
    assert not np.any(rows.matrix) and not np.any(rows.lower)


def test_border_obstacle_has_one_row_per_obstacle() -> None:
    far = Circle(-5.0, -5.0, 0.3)
    step = context(base_at(0.6, 0.5), goal_xy=(3.0, 0.5), obstacles=(far, OBSTACLE, far))
    rows = BorderObstacle(gain=GAIN, margin=MARGIN, lookahead=0.0).rows(step)
    assert rows.matrix.shape == (3, ROBOT.dof) and rows.engaged
    assert not np.any(rows.matrix[[0, 2]]) and np.any(rows.matrix[1])


inside_offsets = st.tuples(st.floats(0.05, 0.99), st.floats(-math.pi, math.pi))


@NO_DEADLINE
@given(inside_offsets, st.floats(0.1, 3.0), st.lists(finite, min_size=7, max_size=7))
def test_engaged_border_obstacle_pushes_the_base_outward(
    offset: tuple[float, float], beyond: float, free: list[float]
) -> None:
    """Inside, with the obstacle between base and goal, any u on the row moves the base out.

    With no look-ahead the row is -2 (q_xy - c)' u_xy = -gain f (5.27), so the radial velocity
    of the base is gain f / (2 ||q_xy - c||), whatever the tangential velocity and the joints.
    """
    fraction, bearing = offset
    direction = np.array([math.cos(bearing), math.sin(bearing)])
    base = CENTRE + fraction * EXTENDED_RADIUS * direction
    goal = CENTRE - beyond * direction  # straight through the obstacle from the base
    rows = border_rows(base[0], base[1], tuple(goal))
    assert rows.engaged
    offset_xy = base - CENTRE
    distance = float(np.linalg.norm(offset_xy))
    f = EXTENDED_RADIUS**2 - distance**2
    expected_row = np.zeros(ROBOT.dof)
    expected_row[:2] = -2.0 * offset_xy
    np.testing.assert_allclose(rows.matrix[0], expected_row, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rows.lower, [-GAIN * f], rtol=1e-12)
    np.testing.assert_array_equal(rows.lower, rows.upper)
    # Any u on the row: a particular solution plus a free tangential part and free other joints.
    radial = offset_xy / distance
    tangent = np.array([-radial[1], radial[0]])
    u = np.zeros(ROBOT.dof)
    u[:2] = rows.lower[0] / (-2.0 * distance) * radial + free[0] * tangent
    u[2:] = free[1:]
    assert rows.matrix[0] @ u == pytest.approx(rows.lower[0], rel=1e-9, abs=1e-12)
    radial_velocity = float(radial @ u[:2])
    assert radial_velocity == pytest.approx(GAIN * f / (2.0 * distance), rel=1e-9)
    assert radial_velocity > 0.0


@NO_DEADLINE
@given(
    inside_offsets,
    angles,
    st.floats(0.01, 0.3),
    st.floats(0.1, 3.0),
    st.lists(finite, min_size=2, max_size=2),
)
def test_engaged_border_obstacle_with_lookahead_pushes_the_point_ahead_outward(
    offset: tuple[float, float],
    phi: float,
    lookahead: float,
    beyond: float,
    free: list[float],
) -> None:
    """The row holds exactly for the base motions whose point p = axle + d (cos phi, sin phi)

    moves outward at gain f / (2 ||p - c||), f = (R + d)^2 - ||p - c||^2, p' taken from
    (x', y', phi') as p' = (x' - d sin(phi) phi', y' + d cos(phi) phi').
    """
    fraction, bearing = offset
    direction = np.array([math.cos(bearing), math.sin(bearing)])
    heading = np.array([math.cos(phi), math.sin(phi)])
    radius = EXTENDED_RADIUS + lookahead
    point = CENTRE + fraction * radius * direction
    axle = point - lookahead * heading
    goal = CENTRE - beyond * direction
    rows = border_rows(axle[0], axle[1], tuple(goal), phi=phi, lookahead=lookahead)
    assert rows.engaged
    distance = fraction * radius
    f = radius**2 - distance**2
    np.testing.assert_allclose(rows.lower, [-GAIN * f], rtol=1e-9)
    tangent = np.array([-direction[1], direction[0]])
    turn, slide = free
    point_velocity = GAIN * f / (2.0 * distance) * direction + slide * tangent
    u = np.zeros(ROBOT.dof)
    u[0] = point_velocity[0] + lookahead * math.sin(phi) * turn
    u[1] = point_velocity[1] - lookahead * math.cos(phi) * turn
    u[2] = turn
    assert rows.matrix[0] @ u == pytest.approx(rows.lower[0], rel=1e-9, abs=1e-9)
    # Any other radial speed of p breaks the row.
    u[:2] += 0.01 * direction
    assert rows.matrix[0] @ u != pytest.approx(rows.lower[0], rel=1e-9, abs=1e-9)


@pytest.mark.parametrize(("gain", "margin"), [(0.0, 0.05), (-1.0, 0.05), (1.0, -0.01)])
def test_border_obstacle_rejects_bad_parameters(gain: float, margin: float) -> None:
    with pytest.raises(ValueError):
        BorderObstacle(gain=gain, margin=margin)


def test_border_obstacle_rejects_a_negative_lookahead() -> None:
    with pytest.raises(ValueError):
        BorderObstacle(lookahead=-0.1)
