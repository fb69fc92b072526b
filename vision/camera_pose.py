"""Where the ceiling camera hangs over the floor, from the reference marker F0.

F0's square fit (``vision.markers.square_pose``: R, t, F0 in the camera frame) gives the
camera in F0's frame, R^T (0 - t): its height over F0's face, and its optical axis R^T z,
whose angle from F0's downward normal is the camera's tilt. F0 lies flat on the floor, its face
``height_m`` above it, so that is the camera's height and tilt over the floor.

The vision tracker's plane-aware poses take the floor's plane from F0's fit, not from the
camera's axis, so a tilted camera costs them little: markers at the base's height are placed
within 3.2 mm (median) by a level camera, 3.9 mm by one tilted 15 degrees
(tests/vision/test_calibration_tilt.py), the estimator's accuracy either way. What does take
the camera as level is the profile's ``scene.camera``: its ``position`` (x, y, height)
straight down over the simulator's floor, from which the supervisor's sight region
(``components.robot_sight``) places the floor the camera sees; ``shift_of_seen_floor``
measures how far off that is.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sim2d.floor_view import seen_floor
from sim2d.pinhole import PinholeCamera
from vision.markers import Detection, Intrinsics, square_pose
from wbc import dq
from wbc.planar import planar_pose


@dataclass(frozen=True)
class CameraPlacement:
    """The camera over the floor: its optical centre in F0's frame (x, y, m; ``height_m`` over
    the floor), the tilt of its optical axis from straight down and the direction it leans to
    (deg, from F0's x axis towards its y axis), and the heading of its image's x axis in F0."""

    x_m: float
    y_m: float
    height_m: float
    tilt_deg: float
    lean_deg: float
    heading_deg: float

    def describe(self) -> str:
        return (
            f"camera {self.height_m:.3f} m over the floor, tilted {self.tilt_deg:.2f} degrees "
            f"(towards {self.lean_deg:.0f} degrees in F0), over ({self.x_m:.3f}, "
            f"{self.y_m:.3f}) m in F0"
        )


def camera_in_reference(pose_c: np.ndarray) -> np.ndarray:
    """The camera frame in F0's, the inverse of F0's pose in the camera frame."""
    return dq.conj(pose_c)


def placement_of(pose_c: np.ndarray, reference_height_m: float) -> CameraPlacement:
    """The placement of a camera that sees F0 (its face ``reference_height_m`` over the floor)
    at ``pose_c`` (F0 in the camera frame)."""
    camera = camera_in_reference(pose_c)
    rotation = dq.rotation_matrix(dq.rotation(camera))  # camera axes in F0
    x, y, z = dq.translation(camera)[1:]
    axis, image_x = rotation[:, 2], rotation[:, 0]
    return CameraPlacement(
        float(x),
        float(y),
        float(z) + reference_height_m,
        math.degrees(math.acos(float(np.clip(-axis[2], -1.0, 1.0)))),
        math.degrees(math.atan2(axis[1], axis[0])),
        math.degrees(math.atan2(image_x[1], image_x[0])),
    )


def placement(
    detections: Sequence[Detection],
    size_m: float,
    reference_height_m: float,
    intrinsics: Intrinsics,
) -> tuple[CameraPlacement, np.ndarray]:
    """The median placement over several frames' detections of F0 (robust to the odd frame
    whose square fit takes IPPE's other solution), and the pose of F0 in the camera frame of
    the frame nearest that median."""
    poses = [square_pose(d, size_m, intrinsics)[0] for d in detections]
    placements = [placement_of(p, reference_height_m) for p in poses]
    fields = np.array([[p.x_m, p.y_m, p.height_m, p.tilt_deg] for p in placements])
    median = np.median(fields, axis=0)
    nearest = int(np.argmin(np.abs((fields - median) / [0.01, 0.01, 0.01, 0.1]).sum(axis=1)))
    chosen = placements[nearest]
    return (
        CameraPlacement(*map(float, median), chosen.lean_deg, chosen.heading_deg),
        poses[nearest],
    )


def measured_camera(
    pose_c: np.ndarray,
    reference: tuple[float, float, float, float],
    intrinsics: Intrinsics,
    size: tuple[int, int],
) -> PinholeCamera:
    """The camera that sees F0 at ``pose_c``, placed in the simulator's world through F0, which
    lies there at ``reference`` (x, y, z, yaw); its distortion left out."""
    x0, y0, z0, yaw0 = reference
    pose = dq.mul(planar_pose(x0, y0, yaw0, z0), camera_in_reference(pose_c))
    i = intrinsics
    return PinholeCamera(pose, size[0], size[1], i.fx, i.fy, i.cx, i.cy)


def shift_of_seen_floor(declared: PinholeCamera, measured: PinholeCamera, height_m: float) -> float:
    """The largest distance between the corners of the floor at ``height_m`` the declared camera
    sees and those the measured one sees, m (``ValueError`` if either does not see it whole)."""
    corners = seen_floor(measured, height_m) - seen_floor(declared, height_m)
    return float(np.max(np.linalg.norm(corners, axis=1)))
