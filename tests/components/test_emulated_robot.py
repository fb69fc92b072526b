"""The emulated servos of the simulated robot (components.emulated_robot's ``WorldDevices``)
and the arm driver mapping through the robot description's ``servos:`` alike, against the AX
emulator on a pseudo-terminal: the joints the driver reads are the world's, a joint commanded
forward moves forward whichever way its servo turns."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from components.arm_driver import ArmDriver
from components.emulated_robot import WorldDevices
from components.runtime import Node
from messages.commands import ArmCommand
from messages.header import Header
from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from protocols import dynamixel_v1 as dxl
from sim2d.devices.ax_servos import AXChainEmulator
from sim2d.world import World
from tests.wbc.mapped_servos import mapped_robot
from wbc.robot import MobileManipulator
from wbc.servo_map import ServoMap


@pytest.fixture
def mapped(tmp_path: Path) -> Iterator[tuple[ArmDriver, AXChainEmulator, WorldDevices]]:
    """The driver on the emulated chain of the mapped robot's world, every joint mid-range."""
    path = mapped_robot(tmp_path)
    robot = MobileManipulator.from_yaml(path)
    servos = ServoMap.of(path, robot.arm_dof)
    q0 = np.concatenate(([0.0, 0.0, 0.0], [0.3, -0.5, -0.4, 0.6, 0.2]))
    world = World(robot, q0, [])
    devices = WorldDevices(world, servos)
    link = tmp_path / "servos"
    chain = AXChainEmulator(devices, servos.ids, link=link)
    profile = tmp_path / "profile.yaml"
    profile.write_text(
        f"extends: {DEPLOY / 'hardware.yaml'}\nrobot: {path}\ncomponents:\n"
        f"  - name: arm_driver\n    params: {{port: {link}, answer_timeout_s: 1.0}}\n"
    )
    chain.start()
    try:
        with Node(load_profile(profile), "arm_driver", ArmDriver.params) as node:
            driver = ArmDriver(node)
            try:
                yield driver, chain, devices
            finally:
                driver.shutdown()
    finally:
        chain.stop()


def test_the_driver_reads_the_worlds_joints_through_the_mapping(mapped) -> None:
    driver, chain, devices = mapped
    world = devices.world
    assert driver.connected
    chain.update(0.01)
    driver.read_joints()
    resolution = 1.0 / dxl.POSITION_UNITS_PER_RAD
    np.testing.assert_allclose(driver.present, world.q[3:], atol=resolution)


def test_a_joint_commanded_forward_moves_forward_whichever_way_its_servo_turns(
    mapped,
) -> None:
    driver, chain, devices = mapped
    world, servos = devices.world, devices.servos
    chain.update(0.01)
    driver.read_joints()
    velocities = (0.2, 0.2, -0.2, 0.2, 0.2)
    header = Header(stamp_ns=time.time_ns(), frame="arm", seq=0, source="test")
    written = chain.counters["sync_writes"]
    driver.on_command(
        ArmCommand(header=header, joint_velocities=velocities, joint_names=driver.names)
    )
    deadline = time.monotonic() + 30.0  # a safety net: the emulator's thread takes the write
    while chain.counters["sync_writes"] == written and time.monotonic() < deadline:
        time.sleep(0.001)
    goals = chain.words(dxl.Address.GOAL_POSITION)
    for joint, velocity in enumerate(velocities):
        servo_goal = dxl.angle_of_units(goals[joint])
        ahead = servos.joint_position(joint, servo_goal) - world.q[3 + joint]
        assert np.sign(ahead) == np.sign(velocity), (joint, ahead)
    before = world.q[3:].copy()
    for _ in range(10):
        chain.update(0.01)
        world.command(0.0, 0.0, devices.joints)  # as the emulated robot steps its world
        world.step(0.01)
    assert np.all(np.sign(world.q[3:] - before) == np.sign(velocities))
