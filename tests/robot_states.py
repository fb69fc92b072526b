"""A robot state at a configuration, as the state estimator would publish it with a fix: the
tests' one way to build a ``RobotState`` from a robot and its q."""

from __future__ import annotations

import numpy as np

from messages.header import Header
from messages.state import RobotState
from wbc.robot import BASE_DOF, MobileManipulator


def state_at(
    robot: MobileManipulator, q: np.ndarray, header: Header, valid: bool = True
) -> RobotState:
    """The state of ``robot`` at ``q`` = [x, y, phi, arm joints], its joints named as its
    description names them and its end effector at fkm(q)."""
    return RobotState(
        header=header,
        base_pose=tuple(q[:BASE_DOF]),
        arm_joints=tuple(q[BASE_DOF:]),
        joint_names=robot.joint_names,
        end_effector=tuple(robot.fkm(q)),
        valid=valid,
        age_s=0.0,
    )
