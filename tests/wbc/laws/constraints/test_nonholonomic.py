"""The nonholonomic row (wbc.laws.constraints.nonholonomic; 5.11, 5.12)."""

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
from wbc.laws.constraints.base import LinearRows
from wbc.laws.constraints.nonholonomic import Nonholonomic


@NO_DEADLINE
@given(angles, finite, finite)
def test_nonholonomic_row_is_sin_minus_cos(phi: float, x: float, y: float) -> None:
    rows = Nonholonomic().rows(context(base_at(x, y, phi)))
    assert isinstance(rows, LinearRows) and rows.engaged
    expected = np.zeros((1, ROBOT.dof))
    expected[0, :2] = math.sin(phi), -math.cos(phi)
    np.testing.assert_array_equal(rows.matrix, expected)
    np.testing.assert_array_equal(rows.lower, [0.0])
    np.testing.assert_array_equal(rows.upper, [0.0])


@NO_DEADLINE
@given(angles, finite, finite, st.lists(finite, min_size=5, max_size=5))
def test_unicycle_motion_satisfies_the_nonholonomic_row(
    phi: float, forward: float, turn: float, arm: list[float]
) -> None:
    rows = Nonholonomic().rows(context(base_at(0.3, -0.2, phi)))
    u = np.array([forward * math.cos(phi), forward * math.sin(phi), turn, *arm])
    assert abs((rows.matrix @ u)[0]) <= 1e-12


@NO_DEADLINE
@given(angles, st.floats(0.01, 5.0))
def test_sideways_motion_violates_the_nonholonomic_row(phi: float, speed: float) -> None:
    rows = Nonholonomic().rows(context(base_at(0.0, 0.0, phi)))
    u = np.zeros(ROBOT.dof)
    u[:2] = -speed * math.sin(phi), speed * math.cos(phi)
    assert (rows.matrix @ u)[0] == pytest.approx(-speed)
