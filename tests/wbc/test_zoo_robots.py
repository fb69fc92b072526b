"""The DH robots of the zoo (deploy/robots): the 7-joint arm is Franka's published table, the
hyper-redundant arm alternates yaw and pitch axes, and both load with their collision parts."""

from __future__ import annotations

import numpy as np
from dqrobotics.robots import FrankaEmikaPandaRobot

from profiles.deploy_files import DEPLOY
from wbc import dq
from wbc.robot import BASE_DOF, MobileManipulator

ROBOTS = DEPLOY / "robots"


def test_the_7_joint_arm_is_frankas_modified_dh_table_regrouped() -> None:
    """The arm's pose in its base top equals DQ Robotics' Panda (Craig's table and the 0.107 m
    flange, in its own base frame) at random configurations inside the limits."""
    robot = MobileManipulator.from_yaml(ROBOTS / "arm7_differential.yaml")
    panda = FrankaEmikaPandaRobot.kinematics()
    mount = dq.conj(panda.get_reference_frame().vec8())  # DQ Robotics' mount offset, undone
    rng = np.random.default_rng(7)
    for _ in range(20):
        q = np.concatenate((rng.uniform(-1, 1, 3), rng.uniform(robot.q_min[3:], robot.q_max[3:])))
        frames = robot.frames(q)
        arm = dq.mul(dq.conj(frames[0]), frames[-1])
        theirs = dq.mul(mount, panda.fkm(q[BASE_DOF:]).vec8())
        assert np.allclose(dq.nearest_equivalent(theirs, arm), arm, atol=1e-12)
    assert robot.arm_dof == 7 and robot.dof == 10


def test_the_snake_alternates_yaw_and_pitch_and_lies_straight_at_zero() -> None:
    """Twelve joints 66 mm apart: at q = 0 the chain lies straight ahead at the base top's
    height, joint 1's axis vertical, joint 2's horizontal, and so on."""
    robot = MobileManipulator.from_yaml(ROBOTS / "snake12.yaml")
    assert robot.arm_dof == 12 and robot.dof == 15
    points = robot.link_points(np.zeros(robot.dof))
    height = robot.base.height
    assert np.allclose(points[1:], [[0.066 * i, 0.0, height] for i in range(1, 13)])
    axes = [dq.rotation_matrix(pose[:4])[:, 2] for pose in robot.frames(np.zeros(robot.dof))]
    for index, axis in enumerate(axes[:-1]):  # frame i-1's z is joint i's axis
        assert np.allclose(np.abs(axis), [0, 0, 1] if index % 2 == 0 else [0, 1, 0])


def test_every_link_of_both_arms_is_a_collision_part() -> None:
    """Each arm's links are capsules of the collision model (checked on their axes when the
    robot is built), beside the base's body."""
    seven = MobileManipulator.from_yaml(ROBOTS / "arm7_differential.yaml").collision
    snake = MobileManipulator.from_yaml(ROBOTS / "snake12.yaml").collision
    assert [s.name for s in seven.segments] == ["upper_arm", "forearm", "hand"]
    assert [s.name for s in snake.segments] == [f"link{i}" for i in range(1, 13)]
    assert seven.points[0].name == snake.points[0].name == "base"
