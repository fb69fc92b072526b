"""An ideal pinhole camera and the ceiling camera of a profile's scene (no OpenCV: the components
that only project points do not import it; ``sim2d.camera`` draws the camera's images).

A world point p_w maps to camera coordinates p_c = R_c^T (p_w - t_c), with (R_c, t_c) the camera
pose, and to pixels u = fx x_c / z_c + cx, v = fy y_c / z_c + cy (camera z = optical axis; pixel
centres at integer coordinates).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wbc import dq


def read_only(x: np.ndarray) -> np.ndarray:
    """A float copy of ``x`` that cannot be written to."""
    out = np.array(x, dtype=float)
    out.flags.writeable = False
    return out


@dataclass(frozen=True, eq=False)
class PinholeCamera:
    """An ideal pinhole camera; ``pose`` is the camera frame in the world (dual quaternion)."""

    pose: np.ndarray
    width: int = 640
    height: int = 480
    fx: float = 600.0
    fy: float = 600.0
    cx: float = 319.5
    cy: float = 239.5

    def __post_init__(self) -> None:
        if np.shape(self.pose) != (8,) or not dq.is_unit(np.asarray(self.pose, float)):
            raise ValueError(f"camera pose must be a unit dual quaternion (8,), got {self.pose!r}")
        object.__setattr__(self, "pose", read_only(self.pose))

    def matrix(self) -> np.ndarray:
        """K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def to_camera(self, points_world: np.ndarray) -> np.ndarray:
        """p_c = R_c^T (p_w - t_c) for (N, 3) world points, m."""
        rotation = dq.rotation_matrix(dq.rotation(self.pose))
        origin = dq.translation(self.pose)[1:]
        return (np.asarray(points_world, float).reshape(-1, 3) - origin) @ rotation

    def project(self, points_world: np.ndarray) -> np.ndarray:
        """(N, 3) world points -> (N, 2) pixels: u = fx x_c / z_c + cx, v = fy y_c / z_c + cy."""
        p = self.to_camera(points_world)
        return np.column_stack(
            (self.fx * p[:, 0] / p[:, 2] + self.cx, self.fy * p[:, 1] / p[:, 2] + self.cy)
        )


def ceiling_pose(x: float, y: float, height: float) -> np.ndarray:
    """The camera at (x, y, height) looking down: a half turn about world x (x_c = x, y_c = -y)."""
    return dq.pose(dq.rotation_quaternion(math.pi, [1.0, 0.0, 0.0]), [x, y, height])


def ceiling_camera(settings) -> PinholeCamera:
    """The camera of a profile's scene (``profiles.scene.Camera``): its intrinsics, above
    ``position`` (x, y, height) looking straight down."""
    c = settings
    return PinholeCamera(
        ceiling_pose(*c.position),
        width=c.width,
        height=c.height,
        fx=c.fx,
        fy=c.fy,
        cx=c.cx,
        cy=c.cy,
    )
