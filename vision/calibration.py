"""A camera's intrinsics from views of a ChArUco board (Zhang's method, as OpenCV runs it).

Each view: OpenCV's ``CharucoDetector`` finds the board's markers and the chessboard corners
between them; ``CharucoBoard.matchImagePoints`` pairs each corner with its place on the board;
``calibrateCameraExtended`` fits K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] and the distortion
(k1 k2 p1 p2 k3; k3 held at 0 unless asked for, as ROS's camera_calibration does) to every
view's corners at once, minimising the RMS reprojection error.

The views are refused, with the rule they break, when they cannot determine the intrinsics:

- fewer than ``MIN_VIEWS`` views show at least ``MIN_CORNERS`` corners not on one line;
- their corners together span less than ``MIN_SPAN`` of the image's width or height (the
  distortion, largest at the edges, is then extrapolated);
- the board's orientations (its normal in each view) differ by less than
  ``MIN_TILT_SPREAD_DEG``: views of parallel planes leave the focal length undetermined;
- the fit leaves over ``MAX_RMS_PX`` between the corners and their images.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from vision.markers import Intrinsics

MIN_CORNERS = 8
"""Chessboard corners a view must show to be used."""
MIN_VIEWS = 10
"""Views needed."""
MIN_SPAN = 0.5
"""The fraction of the image's width and of its height the corners of all views must span."""
MIN_TILT_SPREAD_DEG = 20.0
"""The least angle between the board's normals in two of the views."""
WORST_VIEWS = 3
"""Views named in the result for the error the fit leaves in them."""
MAX_RMS_PX = 2.0
"""A fit that leaves more between the corners and their images is not of this board."""
CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-12)
SUBPIX_GAP_FRACTION = 0.4
"""``cornerSubPix``'s half window, as a fraction of the white gap between a square's corner and
its marker: it sees the corner's four squares and no marker. The detector's own corners were
0.24 px RMS from the truth on the synthetic board, refined so 0.05 px."""
SUBPIX_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-3)


class CalibrationRefused(ValueError):
    """The views cannot determine the intrinsics; the message says which rule they break."""


@dataclass(frozen=True)
class Board:
    """A ChArUco board: ``squares`` (x, y) chessboard squares of side ``square_m`` with an
    ArUco marker of side ``marker_m`` from OpenCV's ``dictionary`` in each white one. The
    default's squares cover 245 x 175 mm: an A4 or US Letter sheet, landscape."""

    squares: tuple[int, int] = (7, 5)
    square_m: float = 0.035
    marker_m: float = 0.026
    dictionary: str = "DICT_5X5_100"

    def __post_init__(self) -> None:
        if min(self.squares) < 2:
            raise ValueError(f"a board needs 2 squares or more each way, got {self.squares}")
        if not 0.0 < self.marker_m < self.square_m:
            raise ValueError(
                f"the marker ({self.marker_m} m) must be smaller than the square "
                f"({self.square_m} m) and positive"
            )
        if not self.dictionary.startswith("DICT_") or not hasattr(cv2.aruco, self.dictionary):
            raise ValueError(f"not an OpenCV ArUco dictionary: {self.dictionary!r}")
        markers = self.squares[0] * self.squares[1] // 2
        if markers > len(self.aruco().bytesList):
            raise ValueError(f"{self.dictionary} has too few markers for {markers}")

    def aruco(self) -> cv2.aruco.Dictionary:
        return cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))

    def charuco(self) -> cv2.aruco.CharucoBoard:
        return cv2.aruco.CharucoBoard(self.squares, self.square_m, self.marker_m, self.aruco())

    def describe(self) -> str:
        x, y = self.squares
        return (
            f"{x}x{y} squares of {1e3 * self.square_m:g} mm, markers of "
            f"{1e3 * self.marker_m:g} mm, {self.dictionary}"
        )


@dataclass(frozen=True, eq=False)
class View:
    """One frame's corners: their places on the board (N, 3), m, and in the image (N, 2), px."""

    name: str
    board_points: np.ndarray
    image_points: np.ndarray


class BoardDetector:
    """Finds a board's corners in grey images."""

    def __init__(self, board: Board) -> None:
        self.board = board.charuco()
        self._detector = cv2.aruco.CharucoDetector(self.board)
        self._gap = 0.5 * (board.square_m - board.marker_m) / board.square_m

    def detect(self, name: str, image: np.ndarray) -> View | None:
        """The view of ``image``, or None when it shows fewer than ``MIN_CORNERS`` corners or
        all of them on one line."""
        corners, ids, _, _ = self._detector.detectBoard(image)
        if ids is None or len(ids) < MIN_CORNERS:
            return None
        if self.board.checkCharucoCornersCollinear(ids):
            return None
        self._refine(image, corners)
        board_points, image_points = self.board.matchImagePoints(corners, ids)
        return View(name, board_points.reshape(-1, 3), image_points.reshape(-1, 2))

    def _refine(self, image: np.ndarray, corners: np.ndarray) -> None:
        """``cornerSubPix`` on each corner, in place, over a window of ``SUBPIX_GAP_FRACTION``
        of the gap, the square's side taken as the median distance to the nearest corner."""
        points = corners.reshape(-1, 2)
        distances = np.linalg.norm(points[:, None] - points[None], axis=2)
        np.fill_diagonal(distances, np.inf)
        side_px = float(np.median(distances.min(axis=1)))
        half = max(2, int(SUBPIX_GAP_FRACTION * self._gap * side_px))
        cv2.cornerSubPix(image, corners, (half, half), (-1, -1), SUBPIX_CRITERIA)


@dataclass(frozen=True)
class Calibration:
    """The fit: intrinsics, image size (width, height), RMS reprojection error (px), the views
    used, the standard deviation of fx fy cx cy (px), the span of the corners (fraction of
    width, height), the largest angle between two views' board normals (deg) and the
    ``WORST_VIEWS`` views the fit leaves the largest RMS error in (name, px), worst first: a
    blurred or misdetected frame shows there."""

    intrinsics: Intrinsics
    size: tuple[int, int]
    rms_px: float
    views: int
    std_px: tuple[float, float, float, float]
    span: tuple[float, float]
    tilt_spread_deg: float
    worst_views: tuple[tuple[str, float], ...] = ()


def spread(views: list[View], size: tuple[int, int]) -> tuple[float, float]:
    """The fraction of the image's width and height between the outermost corners of all views."""
    points = np.concatenate([v.image_points for v in views])
    extent = points.max(axis=0) - points.min(axis=0)
    return float(extent[0] / size[0]), float(extent[1] / size[1])


def tilt_spread_deg(views: list[View], size: tuple[int, int]) -> float:
    """The largest angle between the board's normals in two views, deg, each view's pose fitted
    (``SOLVEPNP_IPPE``) through a guessed camera (f = the image's larger side, the centre in
    the middle, no distortion): a board parallel to the image is so with any focal length, so
    the guess tells parallel views from tilted ones without the fit they would spoil."""
    f = float(max(size))
    guess = np.array([[f, 0.0, 0.5 * size[0]], [0.0, f, 0.5 * size[1]], [0.0, 0.0, 1.0]])
    normals = []
    for view in views:
        _, rotation, _ = cv2.solvePnP(
            view.board_points, view.image_points, guess, None, flags=cv2.SOLVEPNP_IPPE
        )
        normals.append(cv2.Rodrigues(rotation)[0][:, 2])
    cosines = np.clip(np.array(normals) @ np.array(normals).T, -1.0, 1.0)
    return float(np.degrees(np.arccos(cosines.min())))


def evenly(views: list[View], most: int) -> list[View]:
    """At most ``most`` of the views, evenly spaced in their order (a video holds many alike)."""
    if len(views) <= most:
        return views
    return [views[round(i * (len(views) - 1) / (most - 1))] for i in range(most)]


def calibrate(views: list[View], size: tuple[int, int], k3: bool = False) -> Calibration:
    """The intrinsics that views of a board taken at image ``size`` (width, height) determine,
    or ``CalibrationRefused`` (see the module docstring)."""
    if len(views) < MIN_VIEWS:
        raise CalibrationRefused(
            f"too few views: {len(views)} show the board with {MIN_CORNERS} corners or more, "
            f"{MIN_VIEWS} are needed"
        )
    span = spread(views, size)
    if min(span) < MIN_SPAN:
        raise CalibrationRefused(
            f"views too alike: their corners span {100 * span[0]:.0f} % of the image's width "
            f"and {100 * span[1]:.0f} % of its height, {100 * MIN_SPAN:.0f} % of each is "
            "needed: show the board near the image's edges and corners too"
        )
    tilt = tilt_spread_deg(views, size)
    if tilt < MIN_TILT_SPREAD_DEG:
        raise CalibrationRefused(
            f"views too alike: the board's orientations differ by {tilt:.1f} degrees at most, "
            f"{MIN_TILT_SPREAD_DEG:g} are needed: tilt the board 20 to 45 degrees towards the "
            "camera in some views, each way"
        )
    flags = 0 if k3 else cv2.CALIB_FIX_K3
    try:
        rms, matrix, distortion, _, _, std, _, per_view = cv2.calibrateCameraExtended(
            [v.board_points.astype(np.float32) for v in views],
            [v.image_points.astype(np.float32) for v in views],
            size,
            None,
            None,
            flags=flags,
            criteria=CRITERIA,
        )
    except cv2.error as error:
        raise CalibrationRefused(f"OpenCV could not calibrate: {error.err}") from error
    if rms > MAX_RMS_PX:
        raise CalibrationRefused(
            f"the fit leaves {rms:.2f} px RMS between the corners and their images (over "
            f"{MAX_RMS_PX:g}): a board other than the one described, or a blurred one"
        )
    k = matrix
    intrinsics = Intrinsics(
        float(k[0, 0]),
        float(k[1, 1]),
        float(k[0, 2]),
        float(k[1, 2]),
        tuple(float(c) for c in distortion.ravel()[:5]),
    )
    if not all(map(math.isfinite, (rms, *intrinsics.distortion))):
        raise CalibrationRefused("the fit did not converge (not finite)")
    return Calibration(
        intrinsics,
        size,
        float(rms),
        len(views),
        tuple(float(s) for s in std.ravel()[:4]),
        span,
        tilt,
        tuple(
            (views[i].name, float(per_view[i, 0]))
            for i in np.argsort(-per_view.ravel())[:WORST_VIEWS]
        ),
    )
