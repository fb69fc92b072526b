"""Obstacles (wbc/geometry/obstacles.py): circles and solids sorted apart, and the base's least
clearance from the circles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wbc.geometry.obstacles import Circle, least_clearance, split
from wbc.geometry.obstacles3d import Cylinder, Plane


def test_split_keeps_the_circles_and_the_solids_each_in_order() -> None:
    a, b = Circle(0.0, 0.0, 0.1), Circle(1.0, 0.0, 0.2)
    wall, pole = Plane((1.0, 0.0, 0.0), 1.0), Cylinder(0.5, 0.5, 0.05)
    assert split([wall, a, pole, b]) == ((a, b), (wall, pole))
    with pytest.raises(TypeError, match="got tuple"):
        split([(0.0, 0.0, 0.1)])


def test_least_clearance_is_the_smallest_gap_from_the_body_to_a_circle() -> None:
    circles = [Circle(2.0, 0.0, 0.5), Circle(0.0, 3.0, 0.5)]
    bases = np.array([[0.0, 0.0], [1.0, 0.0]])
    assert least_clearance(bases, circles, 0.2) == pytest.approx(1.0 - 0.5 - 0.2)
    assert least_clearance(bases, [Circle(1.0, 0.0, 0.1)], 0.2) < 0.0  # a contact
    assert least_clearance(bases, [], 0.2) == math.inf
