"""Measured joint positions and velocities."""

from __future__ import annotations

from pydantic import model_validator

from messages.base import Finite, Message
from messages.header import Header


class JointStates(Message):
    """Named joints with positions (rad) and velocities (rad/s), index-aligned.

    All three sequences have the same length and names are unique.
    """

    header: Header
    names: tuple[str, ...]
    positions: tuple[Finite, ...]
    velocities: tuple[Finite, ...]

    @model_validator(mode="after")
    def _aligned(self) -> JointStates:
        lengths = (len(self.names), len(self.positions), len(self.velocities))
        if len(set(lengths)) != 1:
            raise ValueError(
                f"names, positions and velocities have lengths {lengths}, expected equal"
            )
        if len(set(self.names)) != len(self.names):
            raise ValueError(f"joint names {self.names} are not unique")
        return self
