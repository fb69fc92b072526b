"""Obstacles in 3-D (wbc/geometry/obstacles3d.py): their exact clearance against independent
formulas, their faces as lower bounds of it, their edges, motion, and refusals that name the
field."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from wbc.geometry.distance_jacobians import (
    point_to_line_squared_distance,
    point_to_plane_distance,
    point_to_point_squared_distance,
)
from wbc.geometry.obstacles3d import CORNER, EDGE, EXTENT_M, FACE, RIM, SIDE, Cylinder, Plane
from wbc.geometry.plucker import foot

TABLE = Plane((0.0, 0.0, 1.0), 0.4, ((0.5, -0.4), (1.1, -0.4), (1.1, 0.4), (0.5, 0.4)), "table")
"""A 0.6 x 0.8 m table top 0.4 m high, its near edge at x = 0.5."""
POLE = Cylinder(0.2, -0.3, 0.05, 0.6, "pole")


def box_distance(points: np.ndarray) -> np.ndarray:
    """Signed distance from the box [0.5, 1.1] x [-0.4, 0.4] x (-inf, 0.4], by clamping."""
    low, high = np.array([0.5, -0.4, -np.inf]), np.array([1.1, 0.4, 0.4])
    outside = np.linalg.norm(points - np.clip(points, low, high), axis=1)
    depth = np.minimum(points - low, high - points).min(axis=1)
    return np.where(outside > 0.0, outside, -depth)


def random_points(count: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform([-0.5, -1.5, -0.5], [2.0, 1.5, 1.5], (count, 3))


def test_table_clearance_is_the_distance_from_the_box() -> None:
    points = random_points(2000, seed=1)
    np.testing.assert_allclose(TABLE.clearance(points), box_distance(points), atol=1e-12)


def test_table_clearance_at_known_points() -> None:
    points = np.array(
        [[0.8, 0.0, 0.5], [0.3, 0.0, 0.2], [0.4, 0.0, 0.5], [0.8, 0.0, 0.35], [0.52, 0.0, 0.1]]
    )
    np.testing.assert_allclose(
        TABLE.clearance(points), [0.1, 0.2, math.hypot(0.1, 0.1), -0.05, -0.02], atol=1e-12
    )


def test_pole_clearance_at_known_points() -> None:
    points = np.array([[0.2, -0.1, 0.3], [0.2, -0.3, 0.9], [0.2, 0.0, 0.7], [0.2, -0.32, 0.5]])
    np.testing.assert_allclose(
        POLE.clearance(points), [0.15, 0.3, math.hypot(0.25, 0.1), -0.03], atol=1e-12
    )
    tall = Cylinder(0.2, -0.3, 0.05)
    assert tall.clearance(np.array([0.2, -0.1, 5.0]))[0] == pytest.approx(0.15)


def test_a_wall_is_a_half_space() -> None:
    wall = Plane((-1.0, 0.0, 0.0), -1.5, name="wall")  # the solid is x > 1.5
    np.testing.assert_allclose(
        wall.clearance(np.array([[1.0, 3.0, 0.2], [1.7, 0.0, 0.0]])), [0.5, -0.2], atol=1e-12
    )
    assert wall.edges() == ()


@pytest.mark.parametrize("solid", [TABLE, POLE], ids=["table", "pole"])
def test_every_face_bounds_the_clearance_from_below(solid: Plane | Cylinder) -> None:
    """The solid lies behind each face, so a point's distance from any face's half-space is at
    most its distance from the solid: the constraint keeps a lower bound."""
    points = random_points(500, seed=2)
    exact = solid.clearance(points)
    if isinstance(solid, Plane):
        faces = solid.faces()
        assert len(faces) == 5
        bounds = np.array(
            [[point_to_plane_distance(np.r_[0.0, p], f) for f in faces] for p in points]
        )
    else:
        side = [
            math.sqrt(point_to_line_squared_distance(np.r_[0.0, p], solid.axis)) - solid.radius
            for p in points
        ]
        bounds = np.column_stack((side, points[:, 2] - solid.height))
    assert np.all(bounds <= exact[:, None] + 1e-12)
    inside = exact < 0.0
    np.testing.assert_allclose(bounds.max(axis=1)[inside], exact[inside], atol=1e-12)


def test_table_edges_are_its_rim_and_its_corners() -> None:
    edges = TABLE.edges()
    assert len(edges) == 8
    for edge in edges[:4]:  # the rim: 0.4 high, each along a side, from corner to corner
        ends = [foot(edge.line) + s * edge.line[1:4] for s in (edge.low, edge.high)]
        for end in ends:
            assert end[2] == pytest.approx(0.4)
            assert TABLE.clearance(end)[0] == pytest.approx(0.0, abs=1e-12)
        assert np.linalg.norm(ends[1] - ends[0]) in (pytest.approx(0.6), pytest.approx(0.8))
    for edge in edges[4:]:  # the corners: vertical, from the rim down
        assert edge.low == -math.inf and edge.high == pytest.approx(0.4)
        np.testing.assert_allclose(np.abs(edge.line[1:4]), [0, 0, 1], atol=1e-12)


@pytest.mark.parametrize("solid", [TABLE, POLE], ids=["table", "pole"])
def test_a_moved_obstacle_keeps_its_clearances(solid: Plane | Cylinder) -> None:
    x, y, yaw = 0.75, 0.85, 0.3
    moved = solid.moved(x, y, yaw)
    points = random_points(300, seed=3)
    c, s = math.cos(yaw), math.sin(yaw)
    placed = np.column_stack(
        (
            x + c * points[:, 0] - s * points[:, 1],
            y + s * points[:, 0] + c * points[:, 1],
            points[:, 2],
        )
    )
    np.testing.assert_allclose(moved.clearance(placed), solid.clearance(points), atol=1e-12)
    back = moved.moved(0.0, 0.0, -yaw).moved(-x * c - y * s, x * s - y * c, 0.0)
    np.testing.assert_allclose(back.clearance(points), solid.clearance(points), atol=1e-12)


def test_a_clockwise_footprint_is_taken_counter_clockwise() -> None:
    reversed_table = Plane(TABLE.normal, TABLE.offset, TABLE.footprint[::-1])
    assert set(reversed_table.footprint) == set(TABLE.footprint)
    points = random_points(100, seed=4)
    np.testing.assert_allclose(reversed_table.clearance(points), TABLE.clearance(points))


def test_a_shelf_underside_holds_the_solid_above() -> None:
    shelf = Plane((0.0, 0.0, -1.0), -1.2, ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)))
    np.testing.assert_allclose(
        shelf.clearance(np.array([[0.5, 0.5, 1.0], [0.5, 0.5, 1.3]])), [0.2, -0.1], atol=1e-12
    )
    assert shelf.edges()[4].low == pytest.approx(1.2) and shelf.edges()[4].high == math.inf


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (lambda: Plane((0.0, 0.0, 2.0), 0.3), "normal"),
        (lambda: Plane((0.0, 0.0, math.nan), 0.3), "normal"),
        (lambda: Plane((0.0, 0.0, 1.0), math.inf), "offset"),
        (lambda: Plane((1.0, 0.0, 0.0), 0.3, ((0, 0), (1, 0), (1, 1))), "footprint"),
        (lambda: Plane((0.0, 0.0, 1.0), 0.3, ((0, 0), (1, 0))), "footprint"),
        (
            lambda: Plane((0.0, 0.0, 1.0), 0.3, ((0, 0), (2, 0), (1, 0.2), (2, 2), (0, 2))),
            "footprint",
        ),
        (lambda: Plane((0.0, 0.0, 1.0), 0.3, ((0, 0), (1, 0), (1, 0), (0, 1))), "footprint"),
        (lambda: Cylinder(0.0, 0.0, 0.0), "radius"),
        (lambda: Cylinder(0.0, 0.0, 0.1, -1.0), "height"),
        (lambda: Cylinder(math.nan, 0.0, 0.1), "x, y"),
        (lambda: Cylinder(0.0, 0.0, 1e300), "radius"),
        (lambda: Cylinder(0.0, 0.0, 0.1, 1e300), "height"),
        (lambda: Cylinder(-1e300, 0.0, 0.1), "x, y"),
        (lambda: Plane((0.0, 0.0, 1.0), -1e300), "offset"),
        (lambda: Plane((0.0, 0.0, 1.0), 0.3, ((0, 0), (1e300, 0), (0, 1))), "footprint"),
    ],
)
def test_bad_obstacles_are_refused_naming_the_field(make, field: str) -> None:
    with pytest.raises(ValueError, match=f"^{re.escape(field)}:"):
        make()


def test_a_solid_larger_than_a_scene_is_refused_with_the_bound() -> None:
    """A scene is a few metres: a number beyond EXTENT_M (100 m) is a mistake, said so."""
    with pytest.raises(
        ValueError,
        match=r"^radius: expected a number > 0 and <= 100 m, got "
        r"1e\+300$",
    ):
        Cylinder(0.0, 0.0, 1e300)
    assert Cylinder(0.0, 0.0, EXTENT_M, EXTENT_M).radius == EXTENT_M
    assert Plane((0.0, 0.0, 1.0), -EXTENT_M).offset == -EXTENT_M


def feature_distance(solid: Plane | Cylinder, point: np.ndarray, kind: int, index: int) -> float:
    """The distance of ``point`` from the feature (``kind``, ``index``), by the distances of
    wbc.geometry.distance_jacobians."""
    vec4 = np.r_[0.0, point]
    if kind == FACE:
        return float(point_to_plane_distance(vec4, solid.faces()[index]))
    if kind == EDGE:
        return math.sqrt(point_to_line_squared_distance(vec4, solid.edges()[index].line))
    if kind == CORNER:
        corner = np.r_[0.0, solid.corners()[index]]
        return math.sqrt(point_to_point_squared_distance(vec4, corner))
    radial = math.sqrt(point_to_line_squared_distance(vec4, solid.axis)) - solid.radius
    return radial if kind == SIDE else math.hypot(radial, point[2] - solid.height)


@pytest.mark.parametrize(
    "solid",
    [TABLE, POLE, Plane((0.0, 0.0, -1.0), -1.2, TABLE.footprint)],
    ids=["table", "pole", "shelf"],
)
def test_the_nearest_feature_gives_the_exact_distance(solid: Plane | Cylinder) -> None:
    """Outside, the distance from the feature ``nearest`` names is the distance from the
    solid; inside, the face named is the one the point is least deep behind."""
    points = random_points(3000, seed=5)
    kinds, indices = solid.nearest(points)
    found = [
        feature_distance(solid, p, k, i) for p, k, i in zip(points, kinds, indices, strict=True)
    ]
    np.testing.assert_allclose(found, solid.clearance(points), atol=1e-12)
    expected = {FACE, EDGE, CORNER} if isinstance(solid, Plane) else {SIDE, FACE, RIM}
    assert set(kinds.tolist()) == expected
