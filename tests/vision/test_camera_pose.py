"""Where the ceiling camera hangs over the floor, from the reference marker F0's pose
(vision.camera_pose), and how far a tilt shifts the floor it sees."""

from __future__ import annotations

import math

import pytest

from sim2d.pinhole import PinholeCamera, ceiling_pose
from vision.camera_pose import placement_of, shift_of_seen_floor
from wbc import dq
from wbc.planar import planar_pose


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
