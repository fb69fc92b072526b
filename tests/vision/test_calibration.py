"""The calibration's parts without images: the intrinsics file (vision.camera_file), the rules
that refuse views (vision.calibration) on corners projected exactly, and the camera's placement
over the floor from F0's pose (vision.camera_pose)."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from profiles.deploy_files import DEPLOY
from sim2d.pinhole import PinholeCamera, ceiling_pose
from vision.calibration import (
    MIN_TILT_SPREAD_DEG,
    Board,
    CalibrationRefused,
    View,
    calibrate,
    evenly,
)
from vision.camera_file import CameraFile, camera_file_text, read_camera_file
from vision.camera_pose import placement_of, shift_of_seen_floor
from vision.markers import Intrinsics
from wbc import dq
from wbc.planar import planar_pose

K = np.array([[600.0, 0.0, 320.0], [0.0, 600.0, 240.0], [0.0, 0.0, 1.0]])
SIZE = (640, 480)


def projected_view(tilt_x_deg: float, tilt_y_deg: float, centre: tuple[float, float]) -> View:
    """The board's corners imaged exactly through K (no distortion), the board turned by the
    tilts about the camera's axes, its centre at (x, y, 0.4) m."""
    board = Board()
    points = board.charuco().getChessboardCorners()
    rotation, _ = cv2.Rodrigues(np.radians([tilt_x_deg, tilt_y_deg, 0.0]))
    middle = 0.5 * board.square_m * np.array([*board.squares, 0.0])
    translation = np.array([*centre, 0.4]) - rotation @ middle
    image, _ = cv2.projectPoints(points, cv2.Rodrigues(rotation)[0], translation, K, None)
    return View("projected", points.astype(float), image.reshape(-1, 2))


CENTRES = [(-0.1, -0.07), (0.1, -0.07), (-0.1, 0.07), (0.1, 0.07), (0.0, 0.0)]


def test_exact_views_give_the_camera_back() -> None:
    views = [projected_view(t, -t / 2, c) for t in (-30, 30) for c in CENTRES]
    found = calibrate(views, SIZE)
    assert found.rms_px < 1e-3
    assert (found.intrinsics.fx, found.intrinsics.cy) == pytest.approx((600.0, 240.0), abs=1e-3)


def test_the_rules_refuse_too_few_alike_and_bunched_views() -> None:
    with pytest.raises(CalibrationRefused, match="too few views: 9 show"):
        calibrate([projected_view(30, 0, (0, 0))] * 9, SIZE)
    flat = [projected_view(0, 0, c) for c in CENTRES] * 2
    with pytest.raises(CalibrationRefused, match="orientations differ by 0.0 degrees at most"):
        calibrate(flat, SIZE)
    spread = 0.8 * MIN_TILT_SPREAD_DEG
    slight = [projected_view(t, 0, c) for t in (-spread / 2, spread / 2) for c in CENTRES]
    # Measured through a guessed focal length (640 px here, for 600): about the 16 degrees.
    with pytest.raises(CalibrationRefused, match=r"differ by 1[5-8]\.\d degrees"):
        calibrate(slight, SIZE)
    middle = [projected_view(t, t, (0.0, 0.0)) for t in range(-30, 31, 6)]
    with pytest.raises(CalibrationRefused, match="span 4[0-9] % of the image's width"):
        calibrate(middle, SIZE)


def test_evenly_keeps_the_first_and_the_last() -> None:
    views = [View(str(i), np.zeros((1, 3)), np.zeros((1, 2))) for i in range(100)]
    assert [v.name for v in evenly(views, 5)] == ["0", "25", "50", "74", "99"]
    assert evenly(views[:3], 5) == views[:3]


@pytest.mark.parametrize(
    "board, says",
    [
        (dict(squares=(1, 5)), "2 squares or more"),
        (dict(marker_m=0.04), "must be smaller than the square"),
        (dict(dictionary="DICT_9X9"), "not an OpenCV ArUco dictionary"),
        (dict(squares=(12, 12), dictionary="DICT_4X4_50"), "too few markers for 72"),
    ],
)
def test_a_board_that_cannot_be_says_why(board: dict, says: str) -> None:
    with pytest.raises(ValueError, match=says):
        Board(**board)


def test_the_intrinsics_file_round_trips_and_the_hand_written_one_stays_valid(
    tmp_path: Path,
) -> None:
    hand = read_camera_file(DEPLOY / "lab" / "camera.yaml")
    assert hand.size is None and hand.size_mismatch(1280, 720) == ""
    camera = CameraFile(Intrinsics(610.5, 605.25, 321.0, 236.5, (-0.12, 0.06, 1e-5, 0, 0)), SIZE)
    path = tmp_path / "camera.yaml"
    path.write_text(camera_file_text(camera, "from a test\non two lines"))
    assert path.read_text().startswith("# from a test\n# on two lines\nfx: 610.5000\n")
    assert read_camera_file(path) == camera
    assert "its calibration is for 640x480" in camera.size_mismatch(1280, 720)


@pytest.mark.parametrize(
    "text, says",
    [
        ("fx: 600\nfy: 600\ncx: 320\n", "has no cy"),
        ("[1, 2]", "is not a mapping"),
        ("fx: -1\nfy: 600\ncx: 320\ncy: 240\n", "must be positive"),
        ("fx: 600\nfy: 600\ncx: 320\ncy: 240\ndistortion: [0.1, 0.2]\n", "4, 5, 8, 12 or 14"),
        ("fx: 600\nfy: 600\ncx: 320\ncy: 240\nwidth: 640\n", "has no height"),
        ("fx: .nan\nfy: 600\ncx: 320\ncy: 240\n", "fx is nan"),
    ],
)
def test_a_wrong_intrinsics_file_says_what_is_wrong(tmp_path: Path, text: str, says: str) -> None:
    path = tmp_path / "camera.yaml"
    path.write_text(text)
    with pytest.raises(ValueError, match=says):
        read_camera_file(path)


def test_the_placement_of_a_tilted_camera_over_a_raised_reference() -> None:
    """A camera 2.5 m over the floor at (0.4, -0.3) in F0 (F0's face 0.01 m up, turned 0.5 rad),
    tilted 5 degrees about its x axis."""
    reference = planar_pose(1.0, 2.0, 0.5, 0.01)
    x = 1.0 + 0.4 * math.cos(0.5) + 0.3 * math.sin(0.5)
    y = 2.0 + 0.4 * math.sin(0.5) - 0.3 * math.cos(0.5)
    level = ceiling_pose(x, y, 2.5)
    tilt = dq.pose(dq.rotation_quaternion(math.radians(5.0), [1.0, 0.0, 0.0]), [0, 0, 0])
    camera = dq.mul(level, tilt)
    pose_c = dq.mul(dq.conj(camera), reference)  # F0 in the camera frame
    found = placement_of(pose_c, 0.01)
    assert (found.x_m, found.y_m, found.height_m) == pytest.approx((0.4, -0.3, 2.5), abs=1e-9)
    assert found.tilt_deg == pytest.approx(5.0, abs=1e-9)
    declared = PinholeCamera(level)
    measured = PinholeCamera(camera)
    shift = shift_of_seen_floor(declared, measured, 0.1)
    # The image's centre moves 2.4 tan(5 deg) = 0.21 m on the plane 0.1 m up, its far corners more.
    assert 2.4 * math.tan(math.radians(5.0)) < shift < 0.3
