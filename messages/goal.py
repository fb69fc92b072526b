"""The task given to a controller."""

from __future__ import annotations

from typing import Literal

from pydantic import model_validator

from messages.base import Message, Positive, UnitDualQuaternion, Vector3
from messages.header import Header


class Goal(Message):
    """A desired end-effector pose or position, with optional controller gains.

    ``task == "pose"`` needs ``pose`` (a unit dual quaternion) and takes no
    ``position``; ``task == "position"`` needs ``position`` (m) and takes no
    ``pose``. ``eta`` is the error gain (1/s) and ``beta`` the bound of
    ``||u||_1 <= beta ||e'||_1`` (5.10); ``None`` keeps the controller's own.
    """

    header: Header
    task: Literal["pose", "position"]
    pose: UnitDualQuaternion | None = None
    position: Vector3 | None = None
    eta: Positive | None = None
    beta: Positive | None = None

    @model_validator(mode="after")
    def _target_matches_task(self) -> Goal:
        if self.task == "pose" and (self.pose is None or self.position is not None):
            raise ValueError("a pose task needs a pose and no position")
        if self.task == "position" and (self.position is None or self.pose is not None):
            raise ValueError("a position task needs a position and no pose")
        return self
