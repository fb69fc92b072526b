"""Poses in the floor plane as unit dual quaternions, and back.

A planar pose (x, y, phi) at height z is x = r + eps (1/2) p r with r = cos(phi/2) + k sin(phi/2)
and p = x i + y j + z k (3.15). Going back keeps the yaw of r's rotation of the x axis, so a
pose slightly tilted out of the plane (a measured one) still gives its heading.
"""

from __future__ import annotations

import math

import numpy as np

from wbc import dq


def planar_pose(x: float, y: float, phi: float, z: float = 0.0) -> np.ndarray:
    """The unit dual quaternion of a rotation phi about z and a translation (x, y, z)."""
    return dq.pose(dq.rotation_quaternion(phi, dq.K_[1:]), np.array([x, y, z]))


def planar_of(pose: np.ndarray) -> tuple[float, float, float]:
    """(x, y, phi) of a pose: its translation's x and y, and the heading atan2 of the rotated
    x axis r i r* projected on the plane."""
    p = dq.translation(pose)
    r = dq.rotation(pose)
    axis = dq.qmul(dq.qmul(r, dq.I_), dq.qconj(r))
    return float(p[1]), float(p[2]), math.atan2(axis[2], axis[1])


def height_of(pose: np.ndarray) -> float:
    """The z of a pose's translation."""
    return float(dq.translation(pose)[3])


def tilt_of(pose: np.ndarray) -> float:
    """The angle between a pose's z axis and the vertical, rad."""
    r = dq.rotation(pose)
    axis = dq.qmul(dq.qmul(r, dq.K_), dq.qconj(r))
    return math.acos(max(-1.0, min(1.0, float(axis[3]))))


def wrap(angle: float) -> float:
    """The angle in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def in_frame(
    x: float, y: float, phi: float, frame: tuple[float, float, float]
) -> tuple[float, float, float]:
    """(x, y, phi) seen from a frame at (x0, y0, yaw0): R(-yaw0) ((x, y) - (x0, y0)), phi - yaw0."""
    x0, y0, yaw0 = frame
    c, s = math.cos(yaw0), math.sin(yaw0)
    return c * (x - x0) + s * (y - y0), -s * (x - x0) + c * (y - y0), phi - yaw0


def compose(
    frame: tuple[float, float, float], pose: tuple[float, float, float]
) -> tuple[float, float, float]:
    """A pose (x, y, phi) given in a frame at (x0, y0, yaw0), in the frame's parent:
    (x0, y0) + R(yaw0) (x, y), yaw0 + phi (the inverse of ``in_frame``)."""
    x0, y0, yaw0 = frame
    x, y, phi = pose
    c, s = math.cos(yaw0), math.sin(yaw0)
    return x0 + c * x - s * y, y0 + s * x + c * y, yaw0 + phi


def inverse(pose: tuple[float, float, float]) -> tuple[float, float, float]:
    """The frame's parent seen from the frame: ``in_frame(0, 0, 0, pose)``."""
    return in_frame(0.0, 0.0, 0.0, pose)


def offset_pose(x: float, y: float, z: float, yaw: float, pitch: float, roll: float) -> np.ndarray:
    """The pose of a translation (x, y, z) and the rotation Rz(yaw) Ry(pitch) Rx(roll)."""
    r = dq.qmul(
        dq.qmul(dq.rotation_quaternion(yaw, dq.K_[1:]), dq.rotation_quaternion(pitch, dq.J_[1:])),
        dq.rotation_quaternion(roll, dq.I_[1:]),
    )
    return dq.pose(r, np.array([x, y, z]))


def offset_of(pose: np.ndarray) -> tuple[float, float, float, float, float, float]:
    """(x, y, z, yaw, pitch, roll) of a pose, the inverse of ``offset_pose``: its translation,
    and the angles of R = Rz(yaw) Ry(pitch) Rx(roll) (pitch in [-pi/2, pi/2])."""
    x, y, z = dq.translation(pose)[1:]
    m = dq.rotation_matrix(dq.rotation(pose))
    yaw = math.atan2(m[1, 0], m[0, 0])
    pitch = math.atan2(-m[2, 0], math.hypot(m[0, 0], m[1, 0]))
    roll = math.atan2(m[2, 1], m[2, 2])
    return float(x), float(y), float(z), yaw, pitch, roll
