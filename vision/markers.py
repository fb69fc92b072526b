"""ArUco marker detection and the pose of each marker in the camera frame.

Two estimates of a square marker of side s with corners c_k (top-left, top-right, bottom-right,
bottom-left at (-s/2, s/2), (s/2, s/2), (s/2, -s/2), (-s/2, -s/2) in its frame):

- ``square_pose``: the pose minimising the reprojection error of the four corners (OpenCV's
  IPPE_SQUARE), free in 6 DOF; its depth and tilt are weak at long range.
- ``plane_pose``: for a marker on a known plane n.p = d, the ray through the image of the
  centre meets the plane, and the yaw comes from the marker's x edges (its corners)
  back-projected on it.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from wbc import dq

_UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 50, 1e-12)
"""Fixed-point undistortion to 1e-12 (OpenCV's default of 5 iterations leaves ~2e-4 px)."""


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics (px) and OpenCV distortion coefficients (k1, k2, p1, p2[, k3])."""

    fx: float
    fy: float
    cx: float
    cy: float
    distortion: tuple[float, ...] = ()

    def matrix(self) -> np.ndarray:
        """K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def distortion_array(self) -> np.ndarray:
        """The distortion coefficients as OpenCV takes them (zeros when none are given)."""
        return np.array(self.distortion if self.distortion else (0.0,) * 4, dtype=float)


@dataclass(frozen=True, eq=False)
class Detection:
    """A marker: id and corners (4, 2), px: top-left, top-right, bottom-right, bottom-left,
    refined on the image's corner points (``cornerSubPix``)."""

    id: int
    corners: np.ndarray


SUBPIX_WINDOW_MODULES = 0.6
"""Half the side of ``cornerSubPix``'s search window, in the marker's modules (cells)."""
SUBPIX_CRITERIA = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 30, 0.01)
THRESHOLD_WINDOW_PX = 13
"""The adaptive threshold's window: one size, where OpenCV tries 3, 13 and 23 px by default."""


class MarkerDetector:
    """OpenCV's ArucoDetector for one predefined dictionary, run once per image with its
    corners refined by contour lines (``CORNER_REFINE_CONTOUR``), then each corner refined on
    the image's corner points from there (``cornerSubPix`` over ``SUBPIX_WINDOW_MODULES``). On
    the synthetic ceiling camera this places and turns a marker better than ArUco's own
    sub-pixel refinement or its contour corners (whose yaw is biased by up to 0.54 degree where
    these corners' is by 0.36, and twice as noisy), for half the time of detecting twice; one
    threshold window of ``threshold_window_px`` (a marker's side is some 30 to 50 px there)
    instead of three takes 40 % of the time and places markers as well."""

    def __init__(self, dictionary: int, threshold_window_px: int = THRESHOLD_WINDOW_PX) -> None:
        parameters = cv2.aruco.DetectorParameters()
        parameters.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_CONTOUR
        parameters.adaptiveThreshWinSizeMin = threshold_window_px
        parameters.adaptiveThreshWinSizeMax = threshold_window_px
        aruco = cv2.aruco.getPredefinedDictionary(dictionary)
        self._modules = aruco.markerSize + 2 * parameters.markerBorderBits
        self._detector = cv2.aruco.ArucoDetector(aruco, parameters)

    def detect(self, image: np.ndarray) -> list[Detection]:
        """Every marker of the dictionary found in a grey (H, W) uint8 image, by increasing id."""
        found, ids, _ = self._detector.detectMarkers(image)
        detections = []
        for contour, marker_id in zip(found, () if ids is None else ids.ravel(), strict=True):
            contour = np.asarray(contour, np.float32).reshape(4, 2)
            side = float(np.mean(np.linalg.norm(contour - np.roll(contour, 1, axis=0), axis=1)))
            half = max(2, round(SUBPIX_WINDOW_MODULES * side / self._modules))
            corners = contour.reshape(4, 1, 2).copy()
            cv2.cornerSubPix(image, corners, (half, half), (-1, -1), SUBPIX_CRITERIA)
            detections.append(Detection(int(marker_id), corners.reshape(4, 2).astype(float)))
        return sorted(detections, key=lambda d: d.id)


def square_corners(size_m: float) -> np.ndarray:
    """The corners (4, 3) of a marker of side s in its own frame, in OpenCV's order, m."""
    h = 0.5 * size_m
    return np.array([[-h, h, 0.0], [h, h, 0.0], [h, -h, 0.0], [-h, -h, 0.0]])


def _pose(rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    return dq.pose(dq.quaternion_of_matrix(rotation), translation)


def _reprojection_rms(
    pose_c: np.ndarray, detection: Detection, size_m: float, intrinsics: Intrinsics
) -> float:
    """sqrt(mean_k |pi(R c_k + t) - u_k|^2), px, with pi the distorted projection."""
    rvec, _ = cv2.Rodrigues(dq.rotation_matrix(dq.rotation(pose_c)))
    tvec = dq.translation(pose_c)[1:]
    projected, _ = cv2.projectPoints(
        square_corners(size_m), rvec, tvec, intrinsics.matrix(), intrinsics.distortion_array()
    )
    residual = projected.reshape(4, 2) - detection.corners
    return float(np.sqrt(np.mean(np.sum(residual**2, axis=1))))


def square_pose(
    detection: Detection, size_m: float, intrinsics: Intrinsics
) -> tuple[np.ndarray, float]:
    """The marker pose in the camera frame (unit dual quaternion) and the RMS reprojection error.

    (R, t) = argmin sum_k |pi(R c_k + t) - u_k|^2 over the corners c_k, by SOLVEPNP_IPPE_SQUARE.
    """
    ok, rvec, tvec = cv2.solvePnP(
        square_corners(size_m),
        detection.corners,
        intrinsics.matrix(),
        intrinsics.distortion_array(),
        flags=cv2.SOLVEPNP_IPPE_SQUARE,
    )
    if not ok:
        raise ValueError(f"solvePnP found no pose for marker {detection.id}")
    rotation, _ = cv2.Rodrigues(rvec)
    pose_c = _pose(rotation, tvec.ravel())
    return pose_c, _reprojection_rms(pose_c, detection, size_m, intrinsics)


def _normalised(points_px: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """Undistorted normalised image points (x, y) = K^-1 u, (N, 2), distortion removed."""
    if intrinsics.distortion:
        return cv2.undistortPoints(
            points_px.reshape(-1, 1, 2),
            intrinsics.matrix(),
            intrinsics.distortion_array(),
            criteria=_UNDISTORT_CRITERIA,
        ).reshape(-1, 2)
    return (points_px - [intrinsics.cx, intrinsics.cy]) / [intrinsics.fx, intrinsics.fy]


def _diagonal_intersection(corners: np.ndarray) -> np.ndarray:
    """Where the diagonals c_0 c_2 and c_1 c_3 meet: (c_0 x c_2) x (c_1 x c_3), homogeneous."""
    h = np.column_stack((corners, np.ones(4)))
    point = np.cross(np.cross(h[0], h[2]), np.cross(h[1], h[3]))
    return point[:2] / point[2]


def _on_plane(rays: np.ndarray, normal: np.ndarray, offset: float) -> np.ndarray:
    """p = (d / n.r) r: the points where the rays r (N, 3) through the origin meet n.p = d."""
    return rays * (offset / (rays @ normal))[:, None]


def plane_pose(
    detection: Detection,
    size_m: float,
    intrinsics: Intrinsics,
    plane_normal: np.ndarray,
    plane_offset: float,
) -> tuple[np.ndarray, float]:
    """The pose of a marker lying on the plane {p : n.p = d} (camera frame) and its RMS error, px.

    n is a unit normal pointing from the plane towards the camera (d < 0 in front of it).
    t = (d / n.r) r for the ray r through the intersection of the image diagonals (the image of
    the centre); z = n; x = the unit projection on the plane of
    (P_tr - P_tl) + (P_br - P_bl), the corners P back-projected on the plane; y = z x x.
    """
    normal = np.asarray(plane_normal, float)
    normal = normal / np.linalg.norm(normal)
    corners = _normalised(detection.corners, intrinsics)
    rays = np.column_stack((np.vstack((corners, _diagonal_intersection(corners))), np.ones(5)))
    if np.any(plane_offset / (rays @ normal) <= 0.0):
        raise ValueError(
            f"marker {detection.id}: the plane n.p = {plane_offset} is not in front of the camera"
        )
    points = _on_plane(rays, normal, plane_offset)
    edge = (points[1] - points[0]) + (points[2] - points[3])
    x_axis = edge - normal * (edge @ normal)
    x_axis = x_axis / np.linalg.norm(x_axis)
    rotation = np.column_stack((x_axis, np.cross(normal, x_axis), normal))
    pose_c = _pose(rotation, points[4])
    return pose_c, _reprojection_rms(pose_c, detection, size_m, intrinsics)


def plane_of(reference_pose_c: np.ndarray, height_m: float) -> tuple[np.ndarray, float]:
    """The plane parallel to a reference marker's face, ``height_m`` above it along its z axis.

    n = R z (the reference's z in the camera frame) and d = n.(t + h n) = n.t + h.
    """
    normal = dq.rotation_matrix(dq.rotation(reference_pose_c))[:, 2]
    origin = dq.translation(reference_pose_c)[1:]
    return normal, float(normal @ origin + height_m)
