"""Serial round trips on the emulated devices, through the clients the drivers use.

Run as ``python -m studies.bench.serial_devices [--json]``. On the AX-18A chain emulator at 1 Mbps
(return delay 500 us, the servos' default), with ROBOTIS's dynamixel-sdk: one servo's
present position and speed (a 4-byte read), the Sync Write of a goal and speed per servo of
Little John's five (its description's ``servos``), and the joint-state rate one read per servo
allows. On the X-series chain emulator (protocol 2.0), the same for the OpenManipulator-X's
four servos (Present Velocity and Position, 8 bytes; Profile Velocity and Goal Position), one
Sync Read of all four, and the joint-state rate a Sync Read and a Sync Write a cycle allow.
On the Create 2 emulator, with pyserial: a Drive Direct written until the wheels take it, and
the mean period of the encoder stream.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence

import numpy as np
import serial
from dynamixel_sdk import COMM_SUCCESS, GroupSyncRead, GroupSyncWrite, PacketHandler, PortHandler

from components.servo_bus import open_port
from outputs.stdout import emit, json_text, result_only_stdout
from profiles.deploy_files import ROBOT_FILE
from protocols import create_oi
from protocols import dynamixel_v1 as dxl
from protocols import dynamixel_v2 as dxl2
from sim2d.devices.ax_servos import AXChainEmulator
from sim2d.devices.create2 import Create2Emulator
from sim2d.devices.x_servos import XChainEmulator
from wbc.servo_map import ServoMap

SAMPLES = 300
SERVOS = ServoMap.of(ROBOT_FILE, 5).ids
"""Little John's servo ids, q1 to q5."""


class StillArm:
    def joint_positions(self) -> Sequence[float]:
        return (0.0, -0.2, 0.2, 0.0, 0.5)

    def set_joint_velocities(self, velocities: Sequence[float]) -> None:
        pass


class StillOMX:
    def joint_positions(self) -> Sequence[float]:
        return (0.0, -0.2, 0.2, 0.5)

    def set_joint_velocities(self, velocities: Sequence[float]) -> None:
        pass


class Wheels:
    """Notes when the wheels were last told a speed."""

    def __init__(self) -> None:
        self.told_ns = 0

    def set_wheel_speeds(self, left: float, right: float) -> None:
        self.told_ns = time.perf_counter_ns()

    def encoder_counts(self) -> tuple[int, int]:
        return 0, 0


def figures(values_us: list[float]) -> dict[str, float]:
    return {
        "median_us": round(float(np.median(values_us)), 1),
        "p99_us": round(float(np.percentile(values_us, 99)), 1),
    }


def servo_bus() -> dict:
    with AXChainEmulator(StillArm(), SERVOS) as chain:
        port, packet = PortHandler(chain.port), PacketHandler(1.0)
        open_port(port, 1_000_000)  # as the driver does: see open_port
        reads, writes = [], []
        for index in range(SAMPLES):
            servo = SERVOS[index % len(SERVOS)]
            start = time.perf_counter()
            _, result, _ = packet.readTxRx(port, servo, dxl.Address.PRESENT_POSITION, 4)
            reads.append((time.perf_counter() - start) * 1e6)
            if result != COMM_SUCCESS:
                raise RuntimeError(packet.getTxRxResult(result))
            group = GroupSyncWrite(port, packet, dxl.Address.GOAL_POSITION, 4)
            for servo_id in SERVOS:
                group.addParam(servo_id, [0, 2, 100, 0])
            start = time.perf_counter()
            group.txPacket()
            writes.append((time.perf_counter() - start) * 1e6)
        port.closePort()
    cycle_us = len(SERVOS) * float(np.median(reads)) + float(np.median(writes))
    return {
        "read_one_servo": figures(reads),
        "sync_write_five": figures(writes),
        "joint_state_rate_hz": round(1e6 / cycle_us, 1),
    }


def x_servo_bus() -> dict:
    """The X-series chain of four, protocol 2.0: one read, one Sync Read of all, one Sync
    Write of all, per sample."""
    ids = (1, 2, 3, 4)
    with XChainEmulator(StillOMX(), ids) as chain:
        port, packet = PortHandler(chain.port), PacketHandler(2.0)
        open_port(port, 1_000_000)
        reads, sync_reads, writes = [], [], []
        group = GroupSyncRead(port, packet, dxl2.Address.PRESENT_VELOCITY, 8)
        for servo_id in ids:
            group.addParam(servo_id)
        for index in range(SAMPLES):
            start = time.perf_counter()
            _, result, _ = packet.readTxRx(
                port, ids[index % len(ids)], dxl2.Address.PRESENT_VELOCITY, 8
            )
            reads.append((time.perf_counter() - start) * 1e6)
            start = time.perf_counter()
            result = result or group.txRxPacket()
            sync_reads.append((time.perf_counter() - start) * 1e6)
            if result != COMM_SUCCESS:
                raise RuntimeError(packet.getTxRxResult(result))
            writer = GroupSyncWrite(port, packet, dxl2.Address.PROFILE_VELOCITY, 8)
            for servo_id in ids:
                writer.addParam(servo_id, [*dxl2.value(100, 4), *dxl2.value(2048, 4)])
            start = time.perf_counter()
            writer.txPacket()
            writes.append((time.perf_counter() - start) * 1e6)
        port.closePort()
    cycle_us = float(np.median(sync_reads)) + float(np.median(writes))  # as the driver reads
    return {
        "read_one_servo": figures(reads),
        "sync_read_four": figures(sync_reads),
        "sync_write_four": figures(writes),
        "joint_state_rate_hz": round(1e6 / cycle_us, 1),
    }


def create_link() -> dict:
    wheels = Wheels()
    with Create2Emulator(wheels) as create:
        client = serial.Serial(create.port, create_oi.BAUD, timeout=0.1)
        client.write(bytes([create_oi.START, create_oi.SAFE]))
        time.sleep(0.05)
        latencies = []
        for index in range(SAMPLES // 3):
            before = wheels.told_ns
            start = time.perf_counter_ns()
            client.write(create_oi.drive_direct(100 + index % 2, 100))
            while wheels.told_ns == before:
                time.sleep(0)  # the emulator's reader thread takes it
            latencies.append((wheels.told_ns - start) / 1e3)
        client.write(create_oi.stream_request([create_oi.LEFT_ENCODER, create_oi.RIGHT_ENCODER]))
        parser, stamps = create_oi.StreamParser(), []
        while len(stamps) < 100:
            for _ in parser.feed(client.read(64)):
                stamps.append(time.perf_counter())
        client.close()
    # Frames arrive in bursts when the reader is late: the mean period over 100 frames.
    period_ms = (stamps[-1] - stamps[0]) * 1e3 / (len(stamps) - 1)
    return {"drive_direct_to_wheels": figures(latencies), "stream_period_ms": round(period_ms, 2)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print JSON instead of lines")
    args = parser.parse_args(argv)
    report = {
        "bench": "serial_devices",
        "servos": servo_bus(),
        "x_servos": x_servo_bus(),
        "create": create_link(),
    }
    if args.json:
        emit(json_text(report))
    else:
        for device in ("servos", "x_servos", "create"):
            for name, value in report[device].items():
                emit(f"{device:8} {name:24} {value}")
    return 0


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
