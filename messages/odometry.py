"""Wheel odometry of the differential-drive base."""

from __future__ import annotations

from messages.base import Finite, Message
from messages.header import Header


class BaseOdometry(Message):
    """Encoder counts, distance travelled by each wheel (m), the integrated planar
    pose ``(x, y)`` in m and heading ``phi`` in rad, and the base's forward (m/s)
    and angular (rad/s) velocity."""

    header: Header
    left_encoder: int
    right_encoder: int
    left_distance: Finite
    right_distance: Finite
    x: Finite
    y: Finite
    phi: Finite
    forward_velocity: Finite
    angular_velocity: Finite
