"""A robot state of no particular robot, for tests of the component runtime and its topics."""

from __future__ import annotations

from messages.base import IDENTITY_POSE
from messages.header import Header
from messages.state import RobotState

UNSTAMPED_SEQ = 10**9
"""A seq the publisher must overwrite with its own count."""


def robot_state(base_x: float = 0.25, valid: bool = True) -> RobotState:
    return RobotState(
        header=Header(stamp_ns=1, frame="world", seq=UNSTAMPED_SEQ, source="test"),
        base_pose=(base_x, 0.0, 0.0),
        arm_joints=(0.0, 0.1, 0.2, 0.3, 0.4),
        end_effector=IDENTITY_POSE,
        valid=valid,
        age_s=0.0,
    )
