"""The synthetic ceiling camera (sim2d.camera): rendered markers and discs."""

from __future__ import annotations

import math

import cv2
import numpy as np

from sim2d.camera import BLACK, FLOOR_GREY, WHITE, ImageNoise, PlacedMarker, render
from sim2d.pinhole import PinholeCamera, ceiling_pose
from wbc import dq

DICTIONARY = cv2.aruco.DICT_4X4_50
CAMERA = PinholeCamera(ceiling_pose(0.6, 0.1, 2.5))
CLEAN = ImageNoise(noise_std=0.0, blur_sigma_px=0.0)


def floor_marker(marker_id: int, x: float, y: float, yaw: float, size_m: float = 0.15):
    return PlacedMarker(
        marker_id, size_m, dq.pose(dq.rotation_quaternion(yaw, [0, 0, 1]), [x, y, 0])
    )


def stock_detector() -> cv2.aruco.ArucoDetector:
    parameters = cv2.aruco.DetectorParameters()
    parameters.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    return cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(DICTIONARY), parameters)


def test_rendered_markers_are_found_at_their_projected_corners() -> None:
    markers = [
        floor_marker(7, 0.0, 0.6, 0.3),
        floor_marker(11, 1.2, -0.4, -1.0),
        floor_marker(23, 0.6, 0.1, 2.0),
        floor_marker(42, 1.5, 0.8, math.pi / 2),
    ]
    image = render(CAMERA, markers, DICTIONARY, ImageNoise(0.0, 0.3), np.random.default_rng(0))
    corners, ids, _ = stock_detector().detectMarkers(image)
    assert ids is not None and sorted(ids.ravel()) == [7, 11, 23, 42]
    by_id = {m.id: m for m in markers}
    for found, marker_id in zip(corners, ids.ravel(), strict=True):
        truth = CAMERA.project(by_id[int(marker_id)].corners_world())
        assert np.abs(found.reshape(4, 2) - truth).max() < 0.5


def test_black_modules_cover_their_projected_area_at_their_projected_centroid() -> None:
    """Area antialiasing: sum of darkness = black area in px^2, its centroid = the modules' one."""
    camera = PinholeCamera(ceiling_pose(0.0, 0.0, 1.0))
    marker = floor_marker(3, 0.0013, -0.0021, 0.0, size_m=0.12)
    image = render(camera, [marker], DICTIONARY, CLEAN, np.random.default_rng(0)).astype(float)
    module_px = 600 * 0.12 / 6
    top_left = camera.project(marker.corners_world())[0]
    # a window inside the white quiet zone, holding the whole black square
    u0, v0 = np.ceil(top_left - 0.5 * module_px).astype(int)
    u1, v1 = np.floor(top_left + 6.5 * module_px).astype(int)
    darkness = (WHITE - image[v0 : v1 + 1, u0 : u1 + 1]) / (WHITE - BLACK)
    bits = cv2.aruco.generateImageMarker(cv2.aruco.getPredefinedDictionary(DICTIONARY), 3, 6)
    rows, cols = np.nonzero(bits < 128)
    assert math.isclose(darkness.sum(), len(rows) * module_px**2, rel_tol=1e-3)
    v, u = np.mgrid[v0 : v1 + 1, u0 : u1 + 1]
    centroid = np.array([(darkness * u).sum(), (darkness * v).sum()]) / darkness.sum()
    expected = top_left + module_px * np.array([cols.mean() + 0.5, rows.mean() + 0.5])
    np.testing.assert_allclose(centroid, expected, atol=0.01)


def test_markers_outside_the_view_or_facing_away_are_not_drawn() -> None:
    rng = np.random.default_rng(0)
    blank = render(CAMERA, [], DICTIONARY, CLEAN, rng)
    facing_down = PlacedMarker(
        1, 0.15, dq.pose(dq.rotation_quaternion(math.pi, [1, 0, 0]), [0.6, 0.1, 0.0])
    )
    hidden = [floor_marker(0, 5.0, 0.1, 0.0), floor_marker(2, 0.6, -3.0, 0.4), facing_down]
    np.testing.assert_array_equal(render(CAMERA, hidden, DICTIONARY, CLEAN, rng), blank)
    visible = render(CAMERA, [floor_marker(0, 0.6, 0.1, 0.0)], DICTIONARY, CLEAN, rng)
    assert np.count_nonzero(visible != blank) > 1000
    assert np.all(blank == FLOOR_GREY)


def test_a_disc_is_drawn_as_its_projection() -> None:
    x, y, z, radius, grey = 0.9, 0.5, 0.1, 0.25, 60
    image = render(
        CAMERA, [], DICTIONARY, CLEAN, np.random.default_rng(0), [(x, y, z, radius, grey)]
    )
    centre = np.rint(CAMERA.project(np.array([[x, y, z]]))[0]).astype(int)
    assert image[centre[1], centre[0]] == grey
    coverage = (FLOOR_GREY - image.astype(float)) / (FLOOR_GREY - grey)
    radius_px = 600 * radius / (2.5 - z)
    assert math.isclose(coverage.sum(), math.pi * radius_px**2, rel_tol=5e-3)


def test_the_same_seed_gives_the_same_image() -> None:
    markers = [floor_marker(5, 0.3, 0.2, 0.7)]

    def image(seed: int) -> np.ndarray:
        return render(CAMERA, markers, DICTIONARY, ImageNoise(), np.random.default_rng(seed))

    np.testing.assert_array_equal(image(17), image(17))
    assert np.any(image(17) != image(18))
