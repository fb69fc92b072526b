"""The emulated AX-18A chain (sim2d/devices/ax_servos.py) driven through a real pty by ROBOTIS's
dynamixel-sdk, and by pyserial for the bytes the SDK never sends."""

from __future__ import annotations

import random
from contextlib import nullcontext
from pathlib import Path

from dynamixel_sdk import (
    COMM_RX_TIMEOUT,
    COMM_SUCCESS,
    ERRBIT_ANGLE,
    GroupSyncWrite,
    PacketHandler,
    PortHandler,
)

from protocols import dynamixel_v1 as dxl
from protocols.dynamixel_v1 import Address, Instruction, StatusError
from sim2d.devices.ax_servos import MODEL_NUMBER, AXChainEmulator
from sim2d.devices.servo_chain import IntegratingJoints
from tests.sim2d.devices.conftest import Exchange, silent_awaited, simulate

IDS = (1, 2, 3, 4, 5)
START_ANGLES = (0.0, 0.4, -0.6, 1.2, -1.0)
CHAIN = AXChainEmulator
PROTOCOL = 1.0
BAUD = 1_000_000
PROBE = 3
"""The servo pinged behind each raw exchange (``exchange``); none of them addresses it."""


def test_every_servo_answers_a_ping_with_the_ax18a_model(
    port: PortHandler, packet: PacketHandler
) -> None:
    for servo_id in IDS:
        assert packet.ping(port, servo_id) == (MODEL_NUMBER, COMM_SUCCESS, 0)


def test_present_position_is_the_backend_angle(
    port: PortHandler, packet: PacketHandler, arm: IntegratingJoints
) -> None:
    arm.angles[3] = -0.25
    for servo_id, angle in zip(IDS, arm.angles, strict=True):
        position, result, error = packet.read2ByteTxRx(port, servo_id, Address.PRESENT_POSITION)
        assert (result, error) == (COMM_SUCCESS, 0)
        assert position == dxl.position_units(angle)


def test_sync_write_moves_every_joint_to_its_goal(
    port: PortHandler, packet: PacketHandler, emulator: AXChainEmulator, arm: IntegratingJoints
) -> None:
    for servo_id in IDS:
        assert packet.write1ByteTxRx(port, servo_id, Address.TORQUE_ENABLE, 1) == (
            COMM_SUCCESS,
            0,
        )
    goals = {1: 700, 2: 300, 3: 512, 4: 650, 5: 400}
    speeds = {1: 300, 2: 0, 3: 1023, 4: 150, 5: 500}
    group = GroupSyncWrite(port, packet, Address.GOAL_POSITION, 4)
    for servo_id in IDS:
        assert group.addParam(servo_id, [*dxl.word(goals[servo_id]), *dxl.word(speeds[servo_id])])
    sent_before = emulator.counters["status_sent"]
    assert group.txPacket() == COMM_SUCCESS
    for servo_id in IDS:
        goal, _, _ = packet.read2ByteTxRx(port, servo_id, Address.GOAL_POSITION)
        assert goal == goals[servo_id]
    assert emulator.counters["status_sent"] == sent_before + len(IDS), "sync write: no answer"
    simulate(emulator, arm, 3)
    moving, result, _ = packet.read1ByteTxRx(port, 1, Address.MOVING)
    assert (moving, result) == (1, COMM_SUCCESS)
    speed, _, _ = packet.read2ByteTxRx(port, 1, Address.PRESENT_SPEED)
    assert speed == 300
    simulate(emulator, arm, 150)
    for servo_id in IDS:
        position, result, error = packet.read2ByteTxRx(port, servo_id, Address.PRESENT_POSITION)
        assert (result, error) == (COMM_SUCCESS, 0)
        assert abs(position - goals[servo_id]) <= 2, servo_id
        assert packet.read1ByteTxRx(port, servo_id, Address.MOVING)[0] == 0


def test_joints_stay_put_with_torque_off(
    port: PortHandler, packet: PacketHandler, emulator: AXChainEmulator, arm: IntegratingJoints
) -> None:
    assert packet.write2ByteTxRx(port, 1, Address.GOAL_POSITION, 900) == (COMM_SUCCESS, 0)
    simulate(emulator, arm, 20)
    assert arm.angles == list(START_ANGLES)


def test_a_silent_servo_times_out_while_the_others_answer(
    port: PortHandler, packet: PacketHandler, emulator: AXChainEmulator
) -> None:
    emulator.fail(3)
    for servo_id in IDS:
        with silent_awaited(port) if servo_id == 3 else nullcontext():
            _, result, _ = packet.read2ByteTxRx(port, servo_id, Address.PRESENT_POSITION)
        assert result == (COMM_RX_TIMEOUT if servo_id == 3 else COMM_SUCCESS), servo_id


def test_an_overloaded_servo_answers_with_the_overload_bit(
    port: PortHandler, packet: PacketHandler, emulator: AXChainEmulator, arm: IntegratingJoints
) -> None:
    emulator.fail(2, silent=False)
    assert packet.write1ByteTxRx(port, 2, Address.TORQUE_ENABLE, 1) == (
        COMM_SUCCESS,
        StatusError.OVERLOAD,
    )
    assert packet.write2ByteTxRx(port, 2, Address.GOAL_POSITION, 100)[0] == COMM_SUCCESS
    simulate(emulator, arm, 10)
    assert arm.angles[1] == START_ANGLES[1]


def test_a_goal_beyond_the_angle_limit_is_clamped_with_the_angle_limit_bit(
    port: PortHandler, packet: PacketHandler
) -> None:
    assert packet.write2ByteTxRx(port, 4, Address.CW_ANGLE_LIMIT, 200) == (COMM_SUCCESS, 0)
    result, error = packet.write2ByteTxRx(port, 4, Address.GOAL_POSITION, 100)
    assert result == COMM_SUCCESS
    assert error & ERRBIT_ANGLE
    assert packet.read2ByteTxRx(port, 4, Address.GOAL_POSITION) == (200, COMM_SUCCESS, 0)


def test_a_bad_checksum_is_answered_with_the_checksum_bit(
    exchange: Exchange, emulator: AXChainEmulator
) -> None:
    ping = dxl.instruction_packet(2, Instruction.PING)
    (status,) = exchange(ping[:-1] + bytes(((ping[-1] + 1) & 0xFF,)))
    assert (status.id, status.error) == (2, StatusError.CHECKSUM)
    assert emulator.counters["bad_checksums"] == 1


def test_an_unknown_instruction_and_a_read_past_the_table_are_refused(exchange: Exchange) -> None:
    (unknown,) = exchange(dxl.instruction_packet(1, 0x42))
    assert unknown.error == StatusError.INSTRUCTION
    (past,) = exchange(dxl.instruction_packet(1, Instruction.READ, bytes((48, 4))))
    assert past.error == StatusError.RANGE


def test_broadcasts_and_absent_ids_get_no_answer(exchange: Exchange) -> None:
    assert exchange(dxl.instruction_packet(dxl.BROADCAST_ID, Instruction.PING)) == []
    assert exchange(dxl.instruction_packet(9, Instruction.PING)) == []


def test_reg_write_waits_for_action(exchange: Exchange) -> None:
    goal = bytes((Address.GOAL_POSITION, *dxl.word(600)))
    (registered,) = exchange(dxl.instruction_packet(5, Instruction.REG_WRITE, goal))
    assert registered.error == 0
    read_goal = dxl.instruction_packet(5, Instruction.READ, bytes((Address.GOAL_POSITION, 2)))
    (before,) = exchange(read_goal)
    assert before.params != dxl.word(600)
    assert exchange(dxl.instruction_packet(dxl.BROADCAST_ID, Instruction.ACTION)) == []
    (after,) = exchange(read_goal)
    assert after.params == dxl.word(600)


def test_the_emulator_survives_garbage(exchange: Exchange, emulator: AXChainEmulator) -> None:
    noise = random.Random(7)
    garbage = bytes(noise.randrange(256) for _ in range(5000))
    flush = bytes(dxl.MAX_PACKET_BYTES)  # completes any frame a garbage length left pending
    answers = exchange(garbage + flush + dxl.instruction_packet(1, Instruction.PING))
    assert answers[-1] == dxl.Packet(1, 0, b"")
    assert emulator.counters["skipped_bytes"] > 0


def test_the_link_names_the_port(arm: IntegratingJoints, tmp_path: Path) -> None:
    link = tmp_path / "ttyAX"
    with AXChainEmulator(arm, IDS, link=link) as chain:
        assert link.resolve() == Path(chain.port).resolve()
    assert not link.exists()
