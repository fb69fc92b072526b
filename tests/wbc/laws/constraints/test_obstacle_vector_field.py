"""The vector-field inequality (wbc/laws/constraints/obstacle_vector_field.py; Marinho,
Adorno et al. 2019)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from tests.wbc.laws.constraints.constraint_steps import (
    NO_DEADLINE,
    ROBOT,
    angles,
    base_at,
    context,
)
from wbc.geometry.obstacles import Circle
from wbc.laws.constraints.obstacle_vector_field import VectorFieldObstacle


def point_distance(q: np.ndarray, obstacle: Circle, margin: float, lookahead: float) -> float:
    """d: the point lookahead ahead of the axle to the circle of R_obs + body + margin + d."""
    px, py = q[0] + lookahead * math.cos(q[2]), q[1] + lookahead * math.sin(q[2])
    radius = obstacle.radius + ROBOT.base.body_radius + margin + lookahead
    return math.hypot(px - obstacle.x, py - obstacle.y) - radius


@NO_DEADLINE
@given(
    st.floats(-1.5, -0.7),
    st.floats(-0.5, 0.5),
    angles,
    st.floats(0.0, 0.2),
    st.lists(st.floats(-1.0, 1.0), min_size=8, max_size=8),
)
@example(-0.703125, 0.0, 0.0, 0.1953125, [0.0] * 8)  # the point inside the margin: found once
def test_the_vector_field_row_is_minus_the_rate_of_the_distance(
    x: float, y: float, phi: float, lookahead: float, u: list[float]
) -> None:
    """-n . p'(u) = -d'(u): checked against a central difference of d along u."""
    obstacle = Circle(0.0, 0.0, 0.1)
    q = base_at(x, y, phi)
    rows = VectorFieldObstacle(2.0, 0.05, lookahead).rows(context(q, obstacles=(obstacle,)))
    step = 1e-6
    direction = np.array(u)
    rate = (
        point_distance(q + step * direction, obstacle, 0.05, lookahead)
        - point_distance(q - step * direction, obstacle, 0.05, lookahead)
    ) / (2 * step)
    assert (rows.matrix @ direction)[0] == pytest.approx(-rate, abs=1e-6)
    # eta_d d, and 0 once the point is inside the margin (d < 0): it may not come nearer
    distance = point_distance(q, obstacle, 0.05, lookahead)
    assert rows.upper[0] == pytest.approx(2.0 * max(distance, 0.0))
    assert rows.lower[0] == -np.inf and rows.engaged  # an inequality: u = 0 always meets it


def test_the_vector_field_inequality_lets_the_base_approach_only_exponentially():
    """Driven straight at the obstacle, the point slows as d shrinks and never reaches it:
    d_k >= d_0 (1 - eta_d dt)^k at steps of dt (d(t) >= d(0) exp(-eta_d t) in continuous time)."""
    obstacle = Circle(1.0, 0.0, 0.1)
    law = VectorFieldObstacle(2.0, 0.05, 0.1)
    q = base_at(0.0, 0.0, 0.0)
    start = point_distance(q, obstacle, 0.05, 0.1)
    for k in range(1, 400):
        rows = law.rows(context(q, obstacles=(obstacle,)))
        forward = min(0.2, rows.upper[0] / -rows.matrix[0, 0])  # as fast as the row allows
        q = q + 0.02 * np.array([forward, 0, 0, 0, 0, 0, 0, 0])
        distance = point_distance(q, obstacle, 0.05, 0.1)
        assert distance >= start * (1.0 - 2.0 * 0.02) ** k - 1e-12 and distance > 0.0
