"""The state's ROS 2 messages: each transform's rotation, composed as quaternions from the
joint's origin and its turn, is the rotation of its 4x4 pose, for the robots of deploy/robots
described by their own YAML (the one read from a URDF takes seconds to load)."""

from pathlib import Path

import numpy as np
import pytest

from messages.header import Header
from ros2.state_messages import tf_message
from ros2.urdf import joints
from tests.robot_states import state_at
from wbc import dq
from wbc.robot import BASE_DOF, MobileManipulator

ROBOTS = [p for p in sorted(Path("deploy/robots").glob("*.yaml")) if "urdf" not in p.read_text()]


@pytest.mark.parametrize("path", ROBOTS, ids=lambda p: p.stem)
def test_each_transforms_quaternion_is_its_poses_rotation(path: Path) -> None:
    robot = MobileManipulator.from_yaml(path)
    tree = joints(robot)
    q = np.random.default_rng(36).uniform(-1.0, 1.0, BASE_DOF + robot.arm_dof)
    state = state_at(robot, q, Header(stamp_ns=1, frame="world", seq=0, source="test"))
    poses = [np.eye(4)] + [joint.transform(q[BASE_DOF:]) for joint in tree]
    poses[0][:2, :2] = [[np.cos(q[2]), -np.sin(q[2])], [np.sin(q[2]), np.cos(q[2])]]
    for transform, pose in zip(tf_message(state, tree).transforms, poses, strict=True):
        r = transform.transform.rotation
        wxyz = np.array([r.w, r.x, r.y, r.z])
        expected = dq.quaternion_of_matrix(pose[:3, :3])
        assert min(np.abs(wxyz - expected).max(), np.abs(wxyz + expected).max()) < 1e-12
