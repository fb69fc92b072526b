"""The estimated state of the whole robot."""

from __future__ import annotations

from messages.base import ArmVector, Message, NonNegative, UnitDualQuaternion, Vector3
from messages.header import Header


class RobotState(Message):
    """The state estimator's output.

    ``base_pose`` is ``(x, y, phi)`` in m, m, rad; ``arm_joints`` the five
    joint angles in rad; ``end_effector`` the pose of the end effector in the
    world frame. ``valid`` is false until the estimator has a fix (then the
    pose fields are best guesses; ``base.IDENTITY_POSE`` stands for an
    unknown end effector); ``age_s`` is how old the newest fused measurement is, in s.
    ``degraded`` says the base pose is carried by odometry alone: the camera lost its marker.
    """

    header: Header
    base_pose: Vector3
    arm_joints: ArmVector
    end_effector: UnitDualQuaternion
    valid: bool
    age_s: NonNegative
    degraded: bool = False

    def configuration(self) -> list[float]:
        """The whole-body configuration ``q = [x, y, phi, q1, ..., q5]``."""
        return [*self.base_pose, *self.arm_joints]
