"""Velocity commands to the base and the arm."""

from __future__ import annotations

from messages.base import ArmVector, Finite, Message
from messages.header import Header


class BaseCommand(Message):
    """Base velocity: forward (m/s) and angular (rad/s), and the same as the
    linear speed of the left and right wheels (m/s)."""

    header: Header
    forward_velocity: Finite
    angular_velocity: Finite
    left_wheel: Finite
    right_wheel: Finite


class ArmCommand(Message):
    """Arm joint velocities, rad/s, one per joint."""

    header: Header
    joint_velocities: ArmVector
