"""A staging candidate and the plane geometry candidates are compared by
(wbc/planning/candidate.py)."""

from __future__ import annotations

import math

import numpy as np

from wbc.geometry.obstacles import Circle
from wbc.planning.candidate import (
    clear_of,
    same_configuration,
    same_kind,
    staging_point,
    within,
)


def test_the_staging_point_stands_the_final_leg_behind_the_base_on_its_heading() -> None:
    base = np.array([1.0, 2.0, math.pi / 2])
    np.testing.assert_allclose(staging_point(base, 0.4), [1.0, 1.6], atol=1e-12)
    np.testing.assert_allclose(staging_point(base, -0.4), [1.0, 2.4], atol=1e-12)


def test_configurations_across_the_heading_wrap_are_the_same() -> None:
    a = np.array([0.5, 0.5, math.pi - 0.005, 0.0, 0.1, 0.2])
    b = np.array([0.5, 0.5, -math.pi + 0.005, 0.0, 0.1, 0.2])
    assert same_configuration(a, b) and same_kind(a, b)
    assert not same_configuration(a, b + [0, 0, 0, 0, 0.05, 0])
    assert same_kind(a, b + [0.05, 0, 0, 0, 1.0, 0]) and not same_kind(a, b + [0.2, 0, 0, 0, 0, 0])


def test_within_a_region_and_clear_of_circles() -> None:
    region = ((1.0, 0.0, 1.0), (0.0, 1.0, 1.0))  # x <= 1, y <= 1
    assert within(region, np.array([0.0, 0.0]), np.array([1.0, 1.0]))
    assert not within(region, np.array([0.0, 0.0]), np.array([1.1, 0.0]))
    assert within((), np.array([100.0, 100.0]))
    circle = Circle(x=0.0, y=0.0, radius=0.5)
    assert clear_of([circle], np.array([0.8, 0.0]), 0.3)
    assert not clear_of([circle], np.array([0.79, 0.0]), 0.3)
