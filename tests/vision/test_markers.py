"""Marker detection and pose (vision/markers.py) on images of the synthetic ceiling camera."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import cache

import cv2
import numpy as np

from sim2d.camera import ImageNoise, PlacedMarker, render
from sim2d.pinhole import PinholeCamera, ceiling_pose
from vision.markers import (
    Detection,
    Intrinsics,
    MarkerDetector,
    plane_of,
    plane_pose,
    square_pose,
)
from wbc import dq

DICTIONARY = cv2.aruco.DICT_4X4_50
SIZE_M = 0.15
CAMERA = PinholeCamera(ceiling_pose(0.6, 0.1, 2.5))
INTRINSICS = Intrinsics(CAMERA.fx, CAMERA.fy, CAMERA.cx, CAMERA.cy)
RAISED_ID = 5
RAISED_HEIGHT_M = 0.1
FRAMES = 6


def placed(marker_id: int, x: float, y: float, z: float, yaw: float) -> PlacedMarker:
    return PlacedMarker(
        marker_id, SIZE_M, dq.pose(dq.rotation_quaternion(yaw, [0, 0, 1]), [x, y, z])
    )


MARKERS = (
    placed(0, -0.3, 0.6, 0.0, 0.3),
    placed(1, 1.2, -0.5, 0.0, -1.0),
    placed(2, 0.3, -0.2, 0.0, 2.0),
    placed(3, 1.5, 0.7, 0.0, 0.7),
    placed(4, -0.4, -0.6, 0.0, -2.5),
    placed(RAISED_ID, 0.9, 0.35, RAISED_HEIGHT_M, 0.4),
)
BASE_DISC = (0.9, 0.35, RAISED_HEIGHT_M, 0.25, 60)


def in_camera(marker: PlacedMarker) -> np.ndarray:
    """The true marker pose in the camera frame, x_cm = x_wc* x_wm."""
    return dq.mul(dq.conj(CAMERA.pose), marker.pose)


def axes(pose: np.ndarray) -> np.ndarray:
    """The rotation matrix [x y z] of a pose."""
    r = dq.rotation(pose)
    return (dq.hamiplus4(r) @ dq.haminus4(dq.qconj(r)))[1:, 1:]


def position(pose: np.ndarray) -> np.ndarray:
    return dq.translation(pose)[1:]


def true_plane(marker: PlacedMarker) -> tuple[np.ndarray, float]:
    normal = axes(in_camera(marker))[:, 2]
    return normal, float(normal @ position(in_camera(marker)))


def yaw_error(estimate: np.ndarray, truth: np.ndarray) -> float:
    """The angle from the true x axis to the estimated one about the true z axis, rad."""
    x_true, x_est, z_true = axes(truth)[:, 0], axes(estimate)[:, 0], axes(truth)[:, 2]
    return math.atan2(float(z_true @ np.cross(x_true, x_est)), float(x_true @ x_est))


@dataclass(frozen=True)
class Frame:
    image: np.ndarray
    detections: dict[int, Detection]
    detect_s: float


@cache
def frames() -> tuple[Frame, ...]:
    detector = MarkerDetector(DICTIONARY)
    out = []
    for seed in range(FRAMES):
        rng = np.random.default_rng(seed)
        image = render(CAMERA, MARKERS, DICTIONARY, ImageNoise(2.0, 0.6), rng, [BASE_DISC])
        start = time.perf_counter()
        found = detector.detect(image)
        out.append(Frame(image, {d.id: d for d in found}, time.perf_counter() - start))
    return tuple(out)


def test_every_marker_is_detected_in_every_frame() -> None:
    for frame in frames():
        assert sorted(frame.detections) == [m.id for m in MARKERS]
        assert all(d.corners.shape == (4, 2) for d in frame.detections.values())
    detect_ms = 1e3 * np.median([f.detect_s for f in frames()])
    print(f"detect 640x480, 6 markers: {detect_ms:.1f} ms")


def test_square_pose_is_within_a_centimetre_laterally() -> None:
    lateral, rms = [], []
    for frame in frames():
        for marker in MARKERS:
            estimate, error = square_pose(frame.detections[marker.id], SIZE_M, INTRINSICS)
            assert dq.is_unit(estimate)
            offset = position(estimate) - position(in_camera(marker))
            lateral.append(np.linalg.norm(offset[:2]))
            rms.append(error)
    print(f"square_pose lateral: median {1e3 * np.median(lateral):.1f} mm")
    assert np.median(lateral) < 0.01
    assert np.max(lateral) < 0.025
    assert np.median(rms) < 0.2


def test_plane_pose_on_the_true_plane_is_within_3_mm_and_half_a_degree() -> None:
    errors, yaws = [], []
    for frame in frames():
        for marker in MARKERS:
            normal, offset = true_plane(marker)
            estimate, rms = plane_pose(
                frame.detections[marker.id], SIZE_M, INTRINSICS, normal, offset
            )
            truth = in_camera(marker)
            errors.append(np.linalg.norm(position(estimate) - position(truth)))
            yaws.append(abs(yaw_error(estimate, truth)))
            np.testing.assert_allclose(axes(estimate)[:, 2], normal, atol=1e-12)
            assert rms < 1.0
    print(
        f"plane_pose: position median {1e3 * np.median(errors):.2f} mm, max"
        f" {1e3 * np.max(errors):.2f} mm; yaw median {np.degrees(np.median(yaws)):.2f} deg,"
        f" max {np.degrees(np.max(yaws)):.2f} deg"
    )
    assert np.median(errors) < 0.003
    assert np.degrees(np.median(yaws)) < 0.5


def test_plane_of_a_reference_gives_the_plane_of_a_raised_marker() -> None:
    reference, raised = MARKERS[2], MARKERS[RAISED_ID]
    normal, offset = plane_of(in_camera(reference), RAISED_HEIGHT_M)
    expected_normal, expected_offset = true_plane(raised)
    np.testing.assert_allclose(normal, expected_normal, atol=1e-12)
    assert math.isclose(offset, expected_offset, abs_tol=1e-12)
    floor = plane_of(dq.conj(CAMERA.pose), 0.0)
    np.testing.assert_allclose(floor[0], true_plane(reference)[0], atol=1e-12)
    assert math.isclose(floor[1], true_plane(reference)[1], abs_tol=1e-12)


def test_raised_marker_from_an_estimated_reference_plane() -> None:
    """Floor plane from the camera pose -> reference marker -> plane 0.1 m up -> raised marker."""
    floor_normal, floor_offset = plane_of(dq.conj(CAMERA.pose), 0.0)
    errors = []
    for frame in frames():
        reference, _ = plane_pose(
            frame.detections[MARKERS[2].id], SIZE_M, INTRINSICS, floor_normal, floor_offset
        )
        normal, offset = plane_of(reference, RAISED_HEIGHT_M)
        estimate, _ = plane_pose(frame.detections[RAISED_ID], SIZE_M, INTRINSICS, normal, offset)
        truth = in_camera(MARKERS[RAISED_ID])
        errors.append(np.linalg.norm(position(estimate) - position(truth)))
    assert np.median(errors) < 0.003


def test_a_wrong_plane_shows_in_the_reprojection_error() -> None:
    marker = MARKERS[1]
    normal, offset = true_plane(marker)
    detection = frames()[0].detections[marker.id]
    _, right = plane_pose(detection, SIZE_M, INTRINSICS, normal, offset)
    _, wrong = plane_pose(detection, SIZE_M, INTRINSICS, normal, offset + 0.2)
    assert right < 0.5 < wrong


def test_distorted_corners_are_undistorted() -> None:
    distorted = Intrinsics(600.0, 600.0, 319.5, 239.5, (-0.25, 0.08, 0.001, -0.0005, 0.0))
    marker = MARKERS[4]
    truth = in_camera(marker)
    h = 0.5 * SIZE_M
    corners_m = np.array([[-h, h, 0.0], [h, h, 0.0], [h, -h, 0.0], [-h, -h, 0.0]])
    rvec, _ = cv2.Rodrigues(axes(truth))
    pixels, _ = cv2.projectPoints(
        corners_m, rvec, position(truth), distorted.matrix(), np.array(distorted.distortion)
    )
    detection = Detection(marker.id, pixels.reshape(4, 2))
    normal, offset = true_plane(marker)
    # square_pose inherits the 5-iteration undistortion inside solvePnP (~2e-4 px).
    for (estimate, rms), tolerance_m, tolerance_px in (
        (plane_pose(detection, SIZE_M, distorted, normal, offset), 1e-9, 1e-6),
        (square_pose(detection, SIZE_M, distorted), 1e-5, 1e-3),
    ):
        np.testing.assert_allclose(position(estimate), position(truth), atol=tolerance_m)
        assert abs(yaw_error(estimate, truth)) < 1e-6
        assert rms < tolerance_px
    ignored, _ = plane_pose(detection, SIZE_M, INTRINSICS, normal, offset)
    assert np.linalg.norm(position(ignored) - position(truth)) > 0.01


def test_a_blank_image_gives_no_detection() -> None:
    image = render(CAMERA, [], DICTIONARY, ImageNoise(), np.random.default_rng(0), [BASE_DISC])
    assert MarkerDetector(DICTIONARY).detect(image) == []


def test_a_marker_of_another_dictionary_is_not_detected() -> None:
    other = cv2.aruco.DICT_6X6_50
    image = render(CAMERA, MARKERS, other, ImageNoise(), np.random.default_rng(0))
    assert MarkerDetector(DICTIONARY).detect(image) == []
    assert len(MarkerDetector(other).detect(image)) == len(MARKERS)
