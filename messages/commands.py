"""Velocity commands to the base and the arm."""

from __future__ import annotations

from typing import Any

from pydantic import model_validator

from messages.base import (
    ArmVector,
    Finite,
    Message,
    check_joint_names,
    with_default_joint_names,
)
from messages.header import Header


class BaseCommand(Message):
    """Base velocity in the base's frame: forward (m/s), angular (rad/s) and, for an
    omnidirectional base, ``lateral_velocity`` (m/s, to the base's left; 0 for the others);
    for a differential base the same as the linear speed of the left and right wheels (m/s),
    0 for the others."""

    header: Header
    forward_velocity: Finite
    angular_velocity: Finite
    left_wheel: Finite
    right_wheel: Finite
    lateral_velocity: Finite = 0.0


class ArmCommand(Message):
    """Arm joint velocities, rad/s (m/s for a prismatic joint), one per joint, named by
    ``joint_names`` as the robot's description names them (index-aligned; ``q1 .. qn`` when
    the sender named none)."""

    header: Header
    joint_velocities: ArmVector
    joint_names: tuple[str, ...]

    @model_validator(mode="before")
    @classmethod
    def _default_names(cls, data: Any) -> Any:
        return with_default_joint_names(data, "joint_velocities")

    @model_validator(mode="after")
    def _names_aligned(self) -> ArmCommand:
        check_joint_names(self.joint_names, self.joint_velocities, "joint_velocities")
        return self
