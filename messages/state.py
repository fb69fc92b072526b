"""The estimated state of the whole robot."""

from __future__ import annotations

from typing import Any

from pydantic import model_validator

from messages.base import (
    ArmVector,
    Message,
    NonNegative,
    UnitDualQuaternion,
    Vector3,
    check_joint_names,
    with_default_joint_names,
)
from messages.header import Header


class RobotState(Message):
    """The state estimator's output.

    ``base_pose`` is ``(x, y, phi)`` in m, m, rad; ``arm_joints`` the arm's joint positions
    (rad, or m for a prismatic joint), named by ``joint_names`` as the robot's description
    names them (index-aligned; ``q1 .. qn`` when the sender named none); ``end_effector`` the
    pose of the end effector in the world frame. ``valid`` is false until the estimator has a
    fix (then the pose fields are best guesses; ``base.IDENTITY_POSE`` stands for an unknown
    end effector); ``age_s`` is how old the newest fused measurement is, in s. ``degraded``
    says the base pose is carried by odometry alone: the camera lost its marker.
    """

    header: Header
    base_pose: Vector3
    arm_joints: ArmVector
    end_effector: UnitDualQuaternion
    valid: bool
    age_s: NonNegative
    degraded: bool = False
    joint_names: tuple[str, ...]

    @model_validator(mode="before")
    @classmethod
    def _default_names(cls, data: Any) -> Any:
        return with_default_joint_names(data, "arm_joints")

    @model_validator(mode="after")
    def _names_aligned(self) -> RobotState:
        check_joint_names(self.joint_names, self.arm_joints, "arm_joints")
        return self

    def configuration(self) -> list[float]:
        """The whole-body configuration ``q = [x, y, phi, q1, ..., qn]``."""
        return [*self.base_pose, *self.arm_joints]
