"""The world follows its robot's description: any number of arm joints, a prismatic joint,
and the base's kind (an omnidirectional base moves sideways as commanded, a fixed one never
moves)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE
from sim2d.world import World
from tests.sim2d.robot_worlds import DT, middle, robot, run
from wbc.robot import MobileManipulator


@pytest.mark.parametrize("name", ["arm7_differential", "snake12"])
def test_every_joint_of_a_long_arm_moves_as_commanded(name: str) -> None:
    arm = robot(name)
    world = World(arm, middle(arm), [])
    speeds = 0.05 * np.arange(1, arm.arm_dof + 1) / arm.arm_dof
    world.command(0.1, 0.1, speeds)
    run(world, 1.0)
    assert world.q.shape == (3 + arm.arm_dof,)
    np.testing.assert_allclose(world.q[3:] - middle(arm)[3:], speeds * 1.0, atol=1e-12)
    np.testing.assert_allclose(world.end_effector, arm.fkm(world.q))
    assert world.q[0] > 1.0  # the wheels drove it forward


def test_a_prismatic_joint_slides_to_its_stop(tmp_path: Path) -> None:
    text = ROBOT_FILE.read_text().replace(
        "type:  [revolute, revolute, revolute, revolute, revolute]",
        "type:  [revolute, revolute, revolute, prismatic, revolute]",
    )
    text = text.replace(
        "joint_min: [-2.5, -1.9, -1.9, -2.5, -1.0]", "joint_min: [-2.5, -1.9, -1.9, 0.0, -1.0]"
    )
    text = text.replace(
        "joint_max: [2.5, 0.4, 0.4, 2.5, 1.0]", "joint_max: [2.5, 0.4, 0.4, 0.1, 1.0]"
    )
    path = tmp_path / "slider.yaml"
    path.write_text(text)
    slider = MobileManipulator.from_yaml(path)
    assert slider.joint_types[3] == "prismatic"
    world = World(slider, np.zeros(slider.dof), [])
    world.command(0.0, 0.0, [0.0, 0.0, 0.0, 0.3, 0.0])  # m/s
    run(world, 0.2)
    assert world.q[6] == pytest.approx(0.06)
    run(world, 0.5)
    assert world.q[6] == 0.1 and world.joint_velocities[3] == 0.0  # at its stop


def test_an_omnidirectional_base_moves_sideways_as_commanded() -> None:
    youbot = robot("youbot")
    start = middle(youbot)
    world = World(youbot, start, [])
    with pytest.raises(ValueError, match="no wheels"):
        world.command(0.1, 0.1, np.zeros(youbot.arm_dof))
    world.drive(0.0, 0.2, 0.0, np.zeros(youbot.arm_dof))  # to its left, 0.2 m/s
    run(world, 1.0)
    heading = start[2]
    moved = world.q[:2] - start[:2]
    left = np.array([-math.sin(heading), math.cos(heading)])
    assert moved @ left == pytest.approx(0.2 * (1.0 - DT), abs=1e-3)  # a step's delay
    assert abs(moved @ np.array([math.cos(heading), math.sin(heading)])) < 1e-6
    assert world.q[2] == pytest.approx(heading, abs=1e-9)
    x, y, phi = world.odometry_pose
    assert (x, y, phi) == pytest.approx((0.0, 0.2 * (1.0 - DT), 0.0), abs=1e-3)
    world.drive(0.1, 0.0, 0.5, np.zeros(youbot.arm_dof))
    run(world, 1.0)
    assert world.q[2] == pytest.approx(heading + 0.5 * (1.0 - DT), abs=1e-3)
    assert world.encoder_counts == (0, 0)


def test_a_fixed_base_never_moves() -> None:
    ur5e = robot("ur5e_fixed")
    start = middle(ur5e)
    world = World(ur5e, start, [])
    world.drive(0.3, 0.3, 1.0, 0.1 * np.ones(ur5e.arm_dof))
    run(world, 0.5)
    np.testing.assert_array_equal(world.q[:3], start[:3])
    np.testing.assert_allclose(world.q[3:], start[3:] + 0.05)
    assert world.odometry_pose == (0.0, 0.0, 0.0)
