"""The emulated X-series chain (sim2d/devices/x_servos.py) driven through a real pty by ROBOTIS's
dynamixel-sdk at protocol 2.0, and by pyserial for the bytes the SDK never sends."""

from __future__ import annotations

from dynamixel_sdk import (
    COMM_RX_TIMEOUT,
    COMM_SUCCESS,
    GroupBulkRead,
    GroupBulkWrite,
    GroupSyncRead,
    GroupSyncWrite,
    PacketHandler,
    PortHandler,
)

from protocols import dynamixel_v2 as dxl
from protocols import x_series_units as x_units
from protocols.dynamixel_v2 import ALERT, Address, HardwareError, Instruction, StatusError
from sim2d.devices.servo_chain import IntegratingJoints
from sim2d.devices.x_servos import MODEL_NUMBER, XChainEmulator
from tests.sim2d.devices.conftest import Exchange, silent_awaited, simulate

IDS = (11, 12, 13, 14)
START_ANGLES = (0.0, 0.4, -0.6, 1.2)
CHAIN = XChainEmulator
PROTOCOL = 2.0
PROBE = 11
"""The servo pinged behind each raw exchange (``exchange``); none of them addresses it."""


def test_a_ping_answers_the_model_and_a_sync_read_every_servo_in_order(
    port: PortHandler, packet: PacketHandler, arm: IntegratingJoints
) -> None:
    assert packet.ping(port, 12) == (MODEL_NUMBER, COMM_SUCCESS, 0)
    arm.angles[3] = -0.25
    group = GroupSyncRead(port, packet, Address.PRESENT_VELOCITY, 8)
    for servo_id in IDS:
        assert group.addParam(servo_id)
    assert group.txRxPacket() == COMM_SUCCESS
    for servo_id, angle in zip(IDS, arm.angles, strict=True):
        assert group.getData(servo_id, Address.PRESENT_POSITION, 4) == x_units.position_units(angle)


def test_sync_write_moves_every_joint_to_its_goal_at_its_profile_velocity(
    port: PortHandler, packet: PacketHandler, emulator: XChainEmulator, arm: IntegratingJoints
) -> None:
    for servo_id in IDS:
        assert packet.write1ByteTxRx(port, servo_id, Address.TORQUE_ENABLE, 1) == (
            COMM_SUCCESS,
            0,
        )
    goals = dict(zip(IDS, (2800, 1500, 2048, 2900), strict=True))
    profiles = dict(zip(IDS, (100, 0, 167, 50), strict=True))
    group = GroupSyncWrite(port, packet, Address.PROFILE_VELOCITY, 8)
    for servo_id in IDS:
        data = dxl.value(profiles[servo_id], 4) + dxl.value(goals[servo_id], 4)
        assert group.addParam(servo_id, list(data))
    assert group.txPacket() == COMM_SUCCESS
    for servo_id in IDS:  # a read answered after the Sync Write was carried out
        assert packet.read4ByteTxRx(port, servo_id, Address.GOAL_POSITION)[0] == goals[servo_id]
    simulate(emulator, arm, 3)
    velocity, result, _ = packet.read4ByteTxRx(port, 11, Address.PRESENT_VELOCITY)
    assert (velocity, result) == (100, COMM_SUCCESS)
    assert packet.read1ByteTxRx(port, 11, Address.MOVING)[0] == 1
    simulate(emulator, arm, 300)
    bulk = GroupBulkRead(port, packet)
    for servo_id in IDS:
        assert bulk.addParam(servo_id, Address.PRESENT_POSITION, 4)
    assert bulk.txRxPacket() == COMM_SUCCESS
    for servo_id in IDS:
        position = bulk.getData(servo_id, Address.PRESENT_POSITION, 4)
        assert abs(position - goals[servo_id]) <= 1, servo_id


def test_bulk_write_writes_each_servo_its_own_entry(
    port: PortHandler, packet: PacketHandler, emulator: XChainEmulator
) -> None:
    group = GroupBulkWrite(port, packet)
    assert group.addParam(11, Address.GOAL_POSITION, 4, list(dxl.value(3000, 4)))
    assert group.addParam(13, Address.PROFILE_VELOCITY, 4, list(dxl.value(40, 4)))
    assert group.txPacket() == COMM_SUCCESS
    assert packet.read4ByteTxRx(port, 11, Address.GOAL_POSITION)[:2] == (3000, COMM_SUCCESS)
    assert packet.read4ByteTxRx(port, 13, Address.PROFILE_VELOCITY)[:2] == (40, COMM_SUCCESS)
    assert emulator.words(Address.PROFILE_VELOCITY) == [0, 0, 40, 0]


def test_writes_the_servo_refuses(
    port: PortHandler, packet: PacketHandler, emulator: XChainEmulator, arm: IntegratingJoints
) -> None:
    """Position limits refuse a goal outside them (Data Limit); EEPROM refuses a write with
    torque on (Access); with torque off nothing moves."""
    assert packet.write4ByteTxRx(port, 11, Address.MIN_POSITION_LIMIT, 1000) == (COMM_SUCCESS, 0)
    assert packet.write4ByteTxRx(port, 11, Address.GOAL_POSITION, 900) == (
        COMM_SUCCESS,
        StatusError.DATA_LIMIT,
    )
    assert packet.write4ByteTxRx(port, 11, Address.GOAL_POSITION, 1100) == (COMM_SUCCESS, 0)
    simulate(emulator, arm, 20)
    assert arm.angles == list(START_ANGLES)
    assert packet.write1ByteTxRx(port, 11, Address.TORQUE_ENABLE, 1) == (COMM_SUCCESS, 0)
    assert packet.write1ByteTxRx(port, 11, Address.OPERATING_MODE, 1) == (
        COMM_SUCCESS,
        StatusError.ACCESS,
    )
    assert packet.write4ByteTxRx(port, 11, Address.PRESENT_POSITION, 0)[1] == StatusError.ACCESS


def test_a_silent_servo_times_out_and_an_overloaded_one_raises_the_alert(
    port: PortHandler, packet: PacketHandler, emulator: XChainEmulator, arm: IntegratingJoints
) -> None:
    emulator.fail(13)
    with silent_awaited(port):
        assert packet.read4ByteTxRx(port, 13, Address.PRESENT_POSITION)[1] == COMM_RX_TIMEOUT
    assert packet.read4ByteTxRx(port, 14, Address.PRESENT_POSITION)[1] == COMM_SUCCESS
    emulator.fail(12, silent=False)
    assert packet.write1ByteTxRx(port, 12, Address.TORQUE_ENABLE, 1) == (COMM_SUCCESS, ALERT)
    error_status, _, error = packet.read1ByteTxRx(port, 12, Address.HARDWARE_ERROR_STATUS)
    assert (error_status, error) == (HardwareError.OVERLOAD, ALERT)
    assert packet.write4ByteTxRx(port, 12, Address.GOAL_POSITION, 100)[0] == COMM_SUCCESS
    simulate(emulator, arm, 10)
    assert arm.angles[1] == START_ANGLES[1]
    assert packet.reboot(port, 12) == (COMM_SUCCESS, 0)
    assert packet.read1ByteTxRx(port, 12, Address.HARDWARE_ERROR_STATUS)[:3:2] == (0, 0)


def test_a_bad_crc_an_unknown_instruction_and_a_stuffed_answer(
    exchange: Exchange, emulator: XChainEmulator
) -> None:
    """A goal whose bytes hold FF FF FD goes in stuffed and comes back unstuffed."""
    ping = dxl.instruction_packet(12, Instruction.PING)
    (status,) = exchange(ping[:-1] + bytes(((ping[-1] + 1) & 0xFF,)))
    assert (status.id, status.error) == (12, StatusError.CRC)
    (unknown,) = exchange(dxl.instruction_packet(12, 0x42))
    assert unknown.error == StatusError.INSTRUCTION
    address = dxl.value(Address.VELOCITY_LIMIT, 2)
    limit = b"\xff\xff\xfd\x00"  # too fast for a real XM430, fine for the bytes
    assert exchange(dxl.write(12, Address.VELOCITY_LIMIT, limit))[0].error == 0
    (read,) = exchange(dxl.instruction_packet(12, Instruction.READ, address + b"\4\0"))
    assert read.data == limit
    assert exchange(dxl.instruction_packet(9, Instruction.PING)) == []
    assert emulator.counters["bad_checksums"] == 1
