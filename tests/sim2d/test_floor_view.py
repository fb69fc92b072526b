"""The floor a ceiling camera sees (sim2d/floor_view.py): its corners project onto the image's
edges, and the region shrunk by a margin keeps that far inside them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim2d.floor_view import camera_region, region_of, seen_floor
from sim2d.pinhole import PinholeCamera, ceiling_pose
from wbc import dq
from wbc.planning.candidate import within


def test_the_corners_of_the_seen_floor_project_onto_the_image_edges() -> None:
    tilted = dq.mul(
        ceiling_pose(0.8, 0.15, 2.5),
        dq.pose(dq.rotation_quaternion(0.1, [0.0, 1.0, 0.0]), [0.0, 0.0, 0.0]),
    )
    camera = PinholeCamera(tilted, width=640, height=480, cx=300.0, cy=250.0)
    corners = seen_floor(camera, 0.092)
    pixels = camera.project(np.column_stack((corners, np.full(4, 0.092))))
    edges = [(-0.5, -0.5), (639.5, -0.5), (639.5, 479.5), (-0.5, 479.5)]
    np.testing.assert_allclose(pixels, edges, atol=1e-9)


def test_a_region_keeps_its_margin_inside_either_way_round() -> None:
    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
    for corners in (square, square[::-1]):
        region = region_of(corners, 0.2)
        assert within(region, (0.2, 0.2), (1.8, 0.8), (1.0, 0.5))
        assert not any(within(region, p) for p in [(0.19, 0.5), (1.0, 0.81), (1.81, 0.5)])


def test_a_camera_that_does_not_see_the_floor_whole_is_refused() -> None:
    below = PinholeCamera(ceiling_pose(0.0, 0.0, 0.05))
    with pytest.raises(ValueError, match="does not look down on the plane z = 0.1 m"):
        seen_floor(below, 0.1)


def test_the_region_is_in_the_frame_of_the_reference_marker() -> None:
    camera = PinholeCamera(ceiling_pose(1.0, 2.0, 2.0), width=600, height=600, cx=299.5, cy=299.5)
    half = 2.0 * 300.0 / 600.0  # the floor under the camera, 1 m each way
    region = camera_region(camera, (1.0, 2.0, math.pi / 2), 0.0, 0.1)
    assert within(region, (half - 0.1 - 1e-9, 0.0), (0.0, -(half - 0.1) + 1e-9))
    assert not within(region, (half - 0.1 + 1e-6, 0.0))
