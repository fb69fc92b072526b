"""Discs in the plane (wbc/planning/disc_geometry.py): their common tangents, the arcs one covers
of another, and whether a segment keeps out of them."""

from __future__ import annotations

import math

import numpy as np

from wbc.geometry.obstacles import Circle
from wbc.planning.disc_geometry import TAU, bitangents, covered, segment_clear

CLEARANCE = 0.215
"""The base's body radius and the LP's margin."""


def test_segment_clear_keeps_the_clearance() -> None:
    circle = [Circle(0.0, 0.0, 0.1)]
    assert segment_clear(np.array([-1.0, 0.32]), np.array([1.0, 0.32]), circle, CLEARANCE)
    assert not segment_clear(np.array([-1.0, 0.3]), np.array([1.0, 0.3]), circle, CLEARANCE)


def test_bitangents_touch_both_discs_at_a_right_angle_to_each_radius() -> None:
    first, second = (np.array([0.0, 0.0]), 0.3), (np.array([2.0, 1.0]), 0.5)
    pairs = bitangents(first, second)
    assert len(pairs) == 4  # apart: two outer and two inner tangents
    for angle1, angle2 in pairs:
        normal1 = np.array([math.cos(angle1), math.sin(angle1)])
        normal2 = np.array([math.cos(angle2), math.sin(angle2)])
        p1, p2 = first[0] + first[1] * normal1, second[0] + second[1] * normal2
        assert abs((p2 - p1) @ normal1) < 1e-12 and abs((p2 - p1) @ normal2) < 1e-12
    assert len(bitangents(first, (np.array([0.5, 0.0]), 0.3))) == 2  # overlapping: outer only
    assert bitangents(first, (np.array([0.05, 0.0]), 0.1)) == []  # one inside the other


def test_covered_is_the_arc_of_a_circle_inside_another_disc() -> None:
    centre = np.array([0.0, 0.0])
    assert covered(centre, 1.0, np.array([3.0, 0.0]), 0.5) is None  # apart
    assert covered(centre, 0.2, np.array([0.1, 0.0]), 1.0) == (0.0, TAU)  # inside it
    start, width = covered(centre, 1.0, np.array([1.0, 0.0]), 1.0)
    assert math.isclose(width, TAU / 3) and math.isclose(start, TAU - math.pi / 3)
