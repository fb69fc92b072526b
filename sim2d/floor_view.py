"""The floor a ceiling camera sees: its image's corners cast on a horizontal plane, and that
quadrilateral as the half-planes a point keeps inside to stay in sight (``wbc.planning.staging``'s
region, which keeps the base where the camera fixes it)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from wbc import dq
from wbc.planar import in_frame

if TYPE_CHECKING:
    from sim2d.pinhole import PinholeCamera

Region = tuple[tuple[float, float, float], ...]
"""Half-planes (a, b, c), (a, b) a unit vector: a point (x, y) is inside where a x + b y <= c
for each."""


def seen_floor(camera: PinholeCamera, height: float) -> np.ndarray:
    """The corners (4, 2) of the plane z = ``height`` the image covers, in the camera's world
    frame: the rays through the image's outer edges (pixel centres at integer coordinates, so
    the edges at -0.5 and width - 0.5) met with the plane."""
    rotation = dq.rotation_matrix(dq.rotation(camera.pose))
    origin = dq.translation(camera.pose)[1:]
    right, bottom = camera.width - 0.5, camera.height - 0.5
    corners = []
    for u, v in ((-0.5, -0.5), (right, -0.5), (right, bottom), (-0.5, bottom)):
        ray = rotation @ np.array([(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0])
        if not ray[2] < 0.0 < origin[2] - height:
            raise ValueError(
                f"the camera does not look down on the plane z = {height:g} m with its whole image"
            )
        corners.append((origin + (height - origin[2]) / ray[2] * ray)[:2])
    return np.array(corners)


def region_of(corners: np.ndarray, margin: float) -> Region:
    """The convex polygon ``corners`` (either way round) shrunk by ``margin`` on every side."""
    x, y = np.asarray(corners, dtype=float).T
    turn = 1.0 if np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) > 0.0 else -1.0
    planes = []
    for (ax, ay), (bx, by) in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        length = float(np.hypot(bx - ax, by - ay))
        a, b = turn * (by - ay) / length, -turn * (bx - ax) / length  # outwards
        planes.append((float(a), float(b), float(a * ax + b * ay) - margin))
    return tuple(planes)


def camera_region(
    camera: PinholeCamera, reference: tuple[float, float, float], height: float, margin: float
) -> Region:
    """Where a point at ``height`` stays ``margin`` inside what ``camera`` sees, in the frame
    of the floor's reference marker, which lies at ``reference`` (x, y, yaw) in the camera's
    world."""
    corners = [in_frame(x, y, 0.0, reference)[:2] for x, y in seen_floor(camera, height)]
    return region_of(np.array(corners), margin)
