"""What the simulator's sensors read off its world (components.sim_sensors), as the robot's
drivers would report it: the joints named as the description names them, the base's odometry
(a differential base's from its wheels, another's from where it started), the ground truth."""

from __future__ import annotations

import numpy as np
import pytest

from components.sim_sensors import SimSensors
from messages.header import Header
from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from sim2d.world import World
from tests.sim2d.robot_worlds import DT, middle, robot, run

HEADER = Header(stamp_ns=0, frame="world", seq=0, source="test")


@pytest.mark.parametrize("name", ["youbot", "ur5e_fixed", "snake12"])
def test_the_sensors_read_the_robots_joints_and_base(name: str) -> None:
    arm = robot(name)
    world = World(arm, middle(arm), [])
    scene = load_profile(DEPLOY / "sim.yaml").scene
    sensors = SimSensors(world, scene, (), scene.arm_obstacles, 508)
    if arm.base.kind == "differential":
        world.command(0.1, 0.1, np.zeros(arm.arm_dof))
    else:
        world.drive(0.1, 0.0, 0.0, np.zeros(arm.arm_dof))
    run(world, 0.5)
    joints = sensors.joints(HEADER)
    assert joints.names == arm.joint_names and len(joints.positions) == arm.arm_dof
    odometry = sensors.odometry(HEADER)
    moved = 0.0 if arm.base.kind == "fixed" else 0.1 * (0.5 - DT)
    ramp = 0.5 * 0.1**2 / 1.0 if arm.base.kind == "differential" else 0.0  # 1 m/s^2 wheels
    assert odometry.x == pytest.approx(moved - ramp, abs=2e-3)
    truth = sensors.truth(HEADER, (0.0, 0.0, 0.0))
    assert truth.arm_joints == tuple(world.q[3:])
