"""The calibration without images (vision.calibration): the camera found from corners projected
exactly, the rules that refuse views, the boards that cannot be."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from vision.calibration import (
    MIN_TILT_SPREAD_DEG,
    Board,
    CalibrationRefused,
    View,
    calibrate,
    evenly,
)

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
