"""The base and arm drivers as processes, against devices on pseudo-terminals: the test itself
plays the Create byte for byte (garbage, bad checksums, a port that vanishes and returns), and
the emulated AX-18A chain plays the servos (one of them falls silent)."""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import yaml

from deploy import query
from messages import codec, topics
from messages.commands import ArmCommand, BaseCommand
from messages.header import Header
from profiles.profile import read_profile_data
from protocols import create_oi
from sim2d.devices.ax_servos import AXChainEmulator
from sim2d.devices.pty_link import PtyLink

if TYPE_CHECKING:
    from tests.components.conftest import System

DEPLOY = Path(__file__).resolve().parents[2] / "deploy"


def driver_system(deployed, tmp_path: Path, name: str, port: Path) -> System:
    """deploy/hardware.yaml with ``name``'s port at ``port``, on a free router port."""
    data = read_profile_data(DEPLOY / "hardware.yaml")
    for spec in data["components"]:
        if spec["name"] == name:
            spec["params"] = {**spec.get("params", {}), "port": str(port)}
    path = tmp_path / "hardware.yaml"
    path.write_text(yaml.safe_dump(data))
    return deployed(path)


class FakeLink(PtyLink):
    """The test on the device's side of a pseudo-terminal."""

    def read(self) -> bytes:
        try:
            return os.read(self.master, 4096)
        except BlockingIOError:
            return b""

    def write(self, data: bytes) -> None:
        os.write(self.master, data)


def status(system: System, name: str):
    return query.statuses(system.router, system.profile.namespace, 0.5).get(name)


def frame(left: int, right: int) -> bytes:
    """A stream frame of the two encoder packets."""
    packets = {create_oi.LEFT_ENCODER: left, create_oi.RIGHT_ENCODER: right}
    return create_oi.stream_frame({i: create_oi.packet_data(i, v) for i, v in packets.items()})


def test_the_base_driver_survives_bad_bytes_and_a_port_that_vanishes(
    deployed, tmp_path: Path, wait_until
) -> None:
    create = FakeLink(tmp_path / "create2")
    system = driver_system(deployed, tmp_path, "base_driver", create.link)
    odometry = system.inbox(topics.BASE_ODOMETRY)
    system.start("base_driver")
    received = bytearray()

    def heard(expected: bytes) -> bool:
        received.extend(create.read())
        return expected in received

    # Start, Safe, then the stream of packets 43 and 44.
    wait_until(lambda: heard(bytes([128, 131, 148, 2, 43, 44])), "Start, Safe and Stream")
    command = system.router.declare_publisher(topics.BASE_COMMAND.key(system.profile.namespace))

    def drive() -> bool:  # until the driver's subscription is matched and it answers
        header = Header(stamp_ns=time.time_ns(), frame="base", seq=0, source="test")
        command.put(codec.encode(BaseCommand(header=header, forward_velocity=0.1,
                                             angular_velocity=0.0, left_wheel=0.1,
                                             right_wheel=0.1)))  # fmt: skip
        time.sleep(0.02)  # commands at 50 Hz, as a controller sends them
        return heard(create_oi.drive_direct(100, 100))


    wait_until(drive, "Drive Direct 100 100 mm/s")
    # Garbage, a bad checksum and a truncated frame, between good frames across the rollover.
    good = frame(65500, 0) + frame(65530, 0)
    broken = bytearray(frame(10, 0))
    broken[-1] ^= 0xFF
    create.write(good + os.urandom(50) + bytes(broken) + frame(20, 0)[:4])
    counts = iter(range(30, 3000, 10))

    def streamed() -> bool:
        """Keep driving and streaming, as the Create does every 15 ms: garbage can hold the
        parser until the next frames complete what it took for one."""
        create.write(frame(next(counts), 0))
        return drive() and any(m.left_encoder >= 30 and m.left_encoder < 65000
                               for m in odometry.messages)  # fmt: skip

    wait_until(streamed, "odometry past the rollover")
    moved = odometry.messages[-1]
    # From 65500 through the rollover: every count forward, the bad frames skipped.
    travelled = (moved.left_encoder - 65500) & 0xFFFF
    assert abs(moved.left_distance - travelled * create_oi.mm_per_count(0.072) / 1000) < 1e-9
    wait_until(lambda: (status(system, "base_driver") or None) is not None
               and status(system, "base_driver").counters["bad_checksums"] >= 1,
               "a counted bad checksum")  # fmt: skip
    # No command for the timeout: the driver stops the wheels itself.
    wait_until(lambda: heard(create_oi.drive_direct(0, 0)), "Drive Direct 0 0 after the timeout")
    # The port vanishes and comes back: the driver opens it again and starts the OI again.
    create.close()
    wait_until(lambda: status(system, "base_driver").state == "no port", "the lost port seen")
    create = FakeLink(tmp_path / "create2")
    received.clear()
    wait_until(lambda: heard(bytes([128, 131, 148, 2, 43, 44])), "the OI started again")
    assert status(system, "base_driver").counters["reconnects"] >= 1
    assert system.processes[0].poll() is None
    create.close()


class Arm:
    """Five joints that move as commanded (the world, for the emulated servos)."""

    def __init__(self) -> None:
        self.q = [0.0, -0.2, 0.2, 0.0, 0.5]
        self.v = [0.0] * 5

    def joint_positions(self) -> Sequence[float]:
        return tuple(self.q)

    def set_joint_velocities(self, velocities: Sequence[float]) -> None:
        self.v = list(velocities)

    def step(self, dt: float) -> None:
        self.q = [q + v * dt for q, v in zip(self.q, self.v, strict=True)]


def test_the_arm_driver_moves_the_servos_and_holds_when_one_falls_silent(
    deployed, tmp_path: Path, wait_until
) -> None:
    arm = Arm()
    link = tmp_path / "servos"
    with AXChainEmulator(arm, link=link) as servos:
        system = driver_system(deployed, tmp_path, "arm_driver", link)
        joints = system.inbox(topics.ARM_JOINT_STATES)
        system.start("arm_driver")
        first = joints.wait_for(lambda m: True, "a joint state")
        assert abs(first.positions[4] - 0.5) < 0.005  # 0.29 degree per unit
        key = topics.ARM_COMMAND.key(system.profile.namespace)
        publisher = system.router.declare_publisher(key)

        def command_and_step() -> bool:
            header = Header(stamp_ns=time.time_ns(), frame="arm", seq=0, source="test")
            velocities = (0.3, 0.0, 0.0, 0.0, -0.3)
            publisher.put(codec.encode(ArmCommand(header=header, joint_velocities=velocities)))
            for _ in range(5):
                servos.update(0.01)
                arm.step(0.01)
            time.sleep(0.02)  # the servos' own time passing
            return arm.q[0] > 0.2 and arm.q[4] < 0.3

        wait_until(command_and_step, "q1 and q5 moving as commanded")
        assert abs(arm.q[1] + 0.2) < 0.01  # a joint commanded to stop holds
        servos.fail(3)
        wait_until(lambda: status(system, "arm_driver").state == "servo 3 silent",
                   "the silent servo reported")  # fmt: skip
        counters = status(system, "arm_driver").counters
        assert counters["servo_timeouts"] >= 1 and counters["holds"] >= 1
        assert system.processes[0].poll() is None
