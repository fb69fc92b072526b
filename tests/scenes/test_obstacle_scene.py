"""The obstacles in Foxglove's 3-D panel (scenes.obstacle_scene) and the parts of the simulated
robot inside them (scenes.penetration_scene), as the views of a ``Viewer``, each read with
nothing but its own schema: every drawn place and size follows from the obstacles message (or
the ground truth) and the model of ``wbc.geometry.obstacles3d``."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest

from messages import topics
from messages.obstacles import Circle, Cylinder, Obstacles, Plane, Solids
from scenes.foxglove_views import (
    CHANNEL_SUFFIX,
    MODEL_EVERY,
    SOLIDS_SUFFIX,
    Viewer,
)
from scenes.obstacle_scene import CIRCLE_HEIGHT_M, UNBOUNDED_HEIGHT_M
from tests.scenes.views_read import HEADER, ROBOT, decode, vector, views
from wbc import dq
from wbc.geometry import scenarios

KEY = "sim/world/obstacles"
TRUTH_KEY = "sim/sim/truth"
TABLE = Plane.of(scenarios.TABLE)
SHELF = Plane(
    name="shelf",
    normal=(0.0, 0.0, -1.0),
    offset=-0.9,
    footprint=((0.0, 1.0), (0.25, 1.4), (0.5, 1.0)),
)
"""An underside 0.9 m up over a triangle given clockwise: the solid is above it."""
WALL = Plane(name="wall", normal=(-0.6, -0.8, 0.0), offset=-1.5)
POLE = Cylinder(name="pole", x=0.2, y=-0.3, radius=0.05, height=0.6)
MAST = Cylinder(name="mast", x=-0.5, y=0.5, radius=0.04)
"""A pole with no top."""


def obstacles(
    seq: int = 3,
    circles: tuple[Circle, ...] = (),
    planes: tuple[Plane, ...] = (),
    cylinders: tuple[Cylinder, ...] = (),
) -> Obstacles:
    return Obstacles(
        header=HEADER.model_copy(update={"seq": seq}),
        circles=circles,
        solids=Solids(planes=planes, cylinders=cylinders),
    )


def entities_by_name(update: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {e["metadata"][0]["value"]: e for e in update.get("entities", [])}


def points_of(primitive: dict[str, Any]) -> np.ndarray:
    """A line or triangle primitive's points, in the order of its indices."""
    points = np.array([vector(p, "xyz") for p in primitive["points"]])
    return points[primitive["indices"]] if "indices" in primitive else points


def area(triangles: np.ndarray) -> float:
    """The total area of a triangle list's (3k, 3) points."""
    a, b, c = triangles[0::3], triangles[1::3], triangles[2::3]
    return float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2)


def polygon_area(footprint: tuple[tuple[float, float], ...]) -> float:
    x, y = np.array(footprint).T
    return float(abs(x @ np.roll(y, -1) - y @ np.roll(x, -1)) / 2)


def rotate(q: dict[str, Any], v: np.ndarray) -> np.ndarray:
    r = np.array(vector(q, "wxyz"))
    return dq.qmul(dq.qmul(r, np.array([0.0, *v])), dq.qconj(r))[1:]


def test_each_circle_is_a_cylinder_from_the_floor_to_its_top() -> None:
    circles = (Circle(x=1.0, y=1.5, radius=0.3, height=0.45), Circle(x=-2.0, y=0.5, radius=0.25))
    drawn = views(Viewer(), KEY, topics.WORLD_OBSTACLES, obstacles(circles=circles))
    update = decode(drawn[CHANNEL_SUFFIX])
    assert [d.get("type") for d in update["deletions"]] == [1]  # ALL: the last ones go
    assert len(update["entities"]) == len(circles)
    for entity, circle in zip(update["entities"], circles, strict=True):
        assert entity["frame_id"] == HEADER.frame
        (cylinder,) = entity["cylinders"]
        height = circle.height or CIRCLE_HEIGHT_M
        assert vector(cylinder["size"], "xyz") == [2 * circle.radius, 2 * circle.radius, height]
        assert vector(cylinder["pose"]["position"], "xyz") == [circle.x, circle.y, height / 2]
    none = views(Viewer(), KEY, topics.WORLD_OBSTACLES, obstacles())
    assert "entities" not in decode(none[CHANNEL_SUFFIX])


def test_a_table_is_its_top_over_the_footprint_and_the_solid_under_it() -> None:
    drawn = views(Viewer(), KEY, topics.WORLD_OBSTACLES, obstacles(planes=(TABLE,)))
    update = decode(drawn[SOLIDS_SUFFIX])
    assert [d.get("type") for d in update["deletions"]] == [1]
    table = entities_by_name(update)["table"]
    assert table["frame_id"] == HEADER.frame
    solid, height = TABLE.solid(), TABLE.offset
    top, body = (points_of(t) for t in table["triangles"])
    # The top: the footprint's polygon at the table's height, covered once.
    assert set(map(tuple, top[:, :2].round(9))) == set(TABLE.footprint)
    assert top[:, 2] == pytest.approx(height)
    assert area(top) == pytest.approx(polygon_area(TABLE.footprint))
    # The solid under it, down to the floor: every vertex on its surface, the sides' area the
    # footprint's perimeter times the height.
    perimeter = sum(
        math.dist(a, b)
        for a, b in zip(TABLE.footprint, TABLE.footprint[1:] + TABLE.footprint[:1], strict=True)
    )
    assert set(body[:, 2].round(9)) == {0.0, height}
    assert area(body) == pytest.approx(perimeter * height)
    (edges,) = table["lines"]
    for points in (top, body, points_of(edges)):
        assert solid.clearance(points) == pytest.approx(0.0, abs=1e-9)
    assert len(points_of(edges)) == 2 * 3 * len(TABLE.footprint)  # rim, floor, corners
    assert table["texts"][0]["text"] == "table"


def test_an_underside_is_drawn_up_from_its_plane() -> None:
    drawn = views(Viewer(), KEY, topics.WORLD_OBSTACLES, obstacles(planes=(SHELF,)))
    shelf = entities_by_name(decode(drawn[SOLIDS_SUFFIX]))["shelf"]
    face, body = (points_of(t) for t in shelf["triangles"])
    height = -SHELF.offset
    assert face[:, 2] == pytest.approx(height)
    assert area(face) == pytest.approx(polygon_area(SHELF.footprint))
    assert set(body[:, 2].round(9)) == {height, round(height + UNBOUNDED_HEIGHT_M, 9)}
    assert SHELF.solid().clearance(body) == pytest.approx(0.0, abs=1e-9)
    # Just above the face is inside the solid, just below is not.
    centre = np.array([*np.mean(SHELF.footprint, axis=0), height])
    assert (
        SHELF.solid().clearance(centre + [0, 0, 0.01])
        < 0
        < SHELF.solid().clearance(centre - [0, 0, 0.01])
    )


def test_a_wall_is_a_thin_box_with_its_front_face_on_the_plane() -> None:
    drawn = views(Viewer(), KEY, topics.WORLD_OBSTACLES, obstacles(planes=(WALL,)))
    (box,) = entities_by_name(decode(drawn[SOLIDS_SUFFIX]))["wall"]["cubes"]
    size = np.array(vector(box["size"], "xyz"))
    centre = np.array(vector(box["pose"]["position"], "xyz"))
    turn = box["pose"]["orientation"]
    normal = np.array(WALL.normal)
    assert rotate(turn, np.array([1.0, 0.0, 0.0])) == pytest.approx(normal)  # x: the normal
    corners = np.array(
        [
            centre + rotate(turn, size / 2 * np.array(signs))
            for signs in itertools.product((-1.0, 1.0), repeat=3)
        ]
    )
    depth = WALL.solid().clearance(corners)
    front = corners @ normal > centre @ normal
    assert depth[front] == pytest.approx(0.0, abs=1e-9)  # the front face on the plane
    assert depth[~front] == pytest.approx(-size[0])  # the box in the solid, its thickness deep
    assert size[1] == size[2] > 1.0  # a wall, not a plate
    assert min(corners[:, 2]) == pytest.approx(0.0, abs=1e-9)  # standing on the floor


def test_a_pole_stands_from_the_floor_to_its_top_and_one_without_a_top_is_tall() -> None:
    drawn = views(Viewer(), KEY, topics.WORLD_OBSTACLES, obstacles(cylinders=(POLE, MAST)))
    found = entities_by_name(decode(drawn[SOLIDS_SUFFIX]))
    for pole, height in ((POLE, POLE.height), (MAST, UNBOUNDED_HEIGHT_M)):
        (cylinder,) = found[pole.name]["cylinders"]
        assert vector(cylinder["size"], "xyz") == pytest.approx(
            [2 * pole.radius, 2 * pole.radius, height]
        )
        assert vector(cylinder["pose"]["position"], "xyz") == pytest.approx(
            [pole.x, pole.y, height / 2]
        )
        top_centre = np.array([pole.x, pole.y, height])
        if pole.height is not None:
            assert pole.solid().clearance(top_centre) == pytest.approx(0.0)
    assert UNBOUNDED_HEIGHT_M > max(p[2] for p in ROBOT.link_points(np.zeros(ROBOT.dof)))


def test_the_solids_go_when_they_change_and_every_model_every_messages() -> None:
    viewer = Viewer()
    sent = [
        SOLIDS_SUFFIX in views(viewer, KEY, topics.WORLD_OBSTACLES, message)
        for message in (
            obstacles(1, planes=(TABLE,)),
            obstacles(2, planes=(TABLE,)),
            obstacles(3, planes=(TABLE, WALL)),
            obstacles(4, planes=(TABLE, WALL)),
            obstacles(MODEL_EVERY, planes=(TABLE, WALL)),
        )
    ]
    assert sent == [True, False, True, False, True]
    # The circles, which the estimator refines with every frame, go with every message.
    circles = (Circle(x=1.0, y=0.0, radius=0.1),)
    assert CHANNEL_SUFFIX in views(
        viewer, KEY, topics.WORLD_OBSTACLES, obstacles(5, circles, planes=(TABLE, WALL))
    )
    # Another key has its own.
    assert SOLIDS_SUFFIX in views(
        viewer, "lab/world/obstacles", topics.WORLD_OBSTACLES, obstacles(6, planes=(TABLE, WALL))
    )
