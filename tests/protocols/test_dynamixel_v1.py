"""Dynamixel protocol 1.0 packets and AX-18A units (protocols/dynamixel_v1.py)."""

from __future__ import annotations

import math

import pytest

from protocols import dynamixel_v1 as dxl
from protocols.dynamixel_v1 import Instruction, Packet, PacketParser, StatusError

EMANUAL_SYNC_WRITE = bytes.fromhex("FF FF FE 0E 83 1E 04 00 10 00 50 01 01 20 02 60 03 67")
"""The e-manual's Sync Write: ids 0 and 1, goal position 0x010 and 0x220, speed 0x150, 0x360."""
PING_1 = bytes.fromhex("FF FF 01 02 01 FB")
"""The e-manual's ping of id 1 and its answer, no error."""
PING_1_STATUS = bytes.fromhex("FF FF 01 02 00 FC")


def test_sync_write_is_the_e_manual_example_byte_for_byte() -> None:
    packet = dxl.sync_write(
        dxl.Address.GOAL_POSITION,
        4,
        {0: dxl.word(0x010) + dxl.word(0x150), 1: dxl.word(0x220) + dxl.word(0x360)},
    )
    assert packet == EMANUAL_SYNC_WRITE


def test_sync_write_refuses_data_of_the_wrong_length() -> None:
    with pytest.raises(dxl.PacketError, match="3 data bytes, 4 expected"):
        dxl.sync_write(dxl.Address.GOAL_POSITION, 4, {1: b"\x00\x02\x00"})


def test_ping_and_its_status() -> None:
    assert dxl.instruction_packet(1, Instruction.PING) == PING_1
    assert dxl.status_packet(1, 0) == PING_1_STATUS


def test_read_packet_and_a_status_with_parameters() -> None:
    read = dxl.instruction_packet(1, Instruction.READ, bytes((dxl.Address.PRESENT_POSITION, 2)))
    assert read == bytes.fromhex("FF FF 01 04 02 24 02 D2")
    status = dxl.status_packet(1, StatusError.ANGLE_LIMIT, dxl.word(512))
    assert status == bytes.fromhex("FF FF 01 04 02 00 02 F6")


def test_packets_outside_the_protocol_are_refused() -> None:
    with pytest.raises(dxl.PacketError, match="id 255"):
        dxl.instruction_packet(255, Instruction.PING)
    with pytest.raises(dxl.PacketError, match="at most 250 expected"):
        dxl.instruction_packet(1, Instruction.WRITE, bytes(245))


def test_parser_frames_instruction_and_status_packets() -> None:
    parser = PacketParser()
    (sync,) = parser.feed(EMANUAL_SYNC_WRITE)
    assert (sync.id, sync.instruction) == (dxl.BROADCAST_ID, Instruction.SYNC_WRITE)
    assert sync.params == EMANUAL_SYNC_WRITE[5:-1]
    (status,) = parser.feed(dxl.status_packet(3, StatusError.CHECKSUM | StatusError.OVERLOAD))
    assert status.error == StatusError.CHECKSUM | StatusError.OVERLOAD
    assert (parser.skipped_bytes, parser.bad_checksums) == (0, 0)


def test_parser_resyncs_after_garbage() -> None:
    parser = PacketParser()
    garbage = bytes.fromhex("00 13 FF 37 FF FF FF")
    assert parser.feed(garbage + PING_1) == [Packet(1, Instruction.PING, b"")]
    assert parser.skipped_bytes == len(garbage)


def test_parser_assembles_packets_fed_byte_by_byte() -> None:
    parser = PacketParser()
    stream = PING_1 + EMANUAL_SYNC_WRITE + PING_1_STATUS
    packets = [packet for byte in stream for packet in parser.feed(bytes((byte,)))]
    assert [p.instruction for p in packets] == [Instruction.PING, Instruction.SYNC_WRITE, 0]
    assert parser.skipped_bytes == 0


def test_parser_reports_a_bad_checksum_and_finds_the_next_packet() -> None:
    parser = PacketParser()
    corrupt = PING_1[:-1] + b"\x00"
    bad, good = parser.feed(corrupt + PING_1)
    assert (bad.id, bad.instruction, bad.checksum_ok) == (1, Instruction.PING, False)
    assert good == Packet(1, Instruction.PING, b"")
    assert parser.bad_checksums == 1


def test_parser_finds_a_packet_that_a_garbage_length_had_swallowed() -> None:
    parser = PacketParser()
    packets = parser.feed(bytes.fromhex("FF FF 05 09") + PING_1 + bytes(3))
    assert [p.checksum_ok for p in packets] == [False, True]
    assert packets[1] == Packet(1, Instruction.PING, b"")


@pytest.mark.parametrize("data", [b"", b"\xff", b"\xff\xff", b"\xff\xff\x01\x00\x00", bytes(256)])
def test_parser_never_raises(data: bytes) -> None:
    parser = PacketParser()
    assert parser.feed(data) == []
    assert parser.feed(PING_1) == [Packet(1, Instruction.PING, b"")]


def test_position_units_centre_and_span() -> None:
    assert dxl.position_units(0.0) == 512
    assert dxl.angle_of_units(512) == 0.0
    span = dxl.angle_of_units(1023) - dxl.angle_of_units(0)
    assert span == pytest.approx(math.radians(300.0), abs=math.radians(0.3))
    assert dxl.position_units(math.radians(150.0)) == 1023
    assert dxl.position_units(-math.radians(150.0)) == 0


def test_position_units_clamp_and_round_trip() -> None:
    assert dxl.position_units(10.0) == 1023
    assert dxl.position_units(-10.0) == 0
    for units in (0, 1, 300, 511, 512, 513, 1000, 1023):
        assert dxl.position_units(dxl.angle_of_units(units)) == units


def test_position_units_refuse_a_non_finite_angle_and_never_overflow() -> None:
    for angle in (math.nan, math.inf, -math.inf):
        with pytest.raises(ValueError, match="non-finite"):
            dxl.position_units(angle)
    assert dxl.position_units(1e308) == 1023 and dxl.position_units(-1e308) == 0


def test_moving_speed() -> None:
    one_rpm = 2.0 * math.pi / 60.0
    assert dxl.moving_speed(0.111 * 300 * one_rpm) == 300
    assert dxl.moving_speed(-0.111 * 300 * one_rpm) == 300
    assert dxl.rad_s_of_speed_units(300) == pytest.approx(0.111 * 300 * one_rpm)
    # Moving Speed 0 means full speed: a speed that rounds to it is no speed at all.
    for still in (0.0, -0.0, 0.4 * dxl.SPEED_RAD_S_PER_UNIT):
        assert dxl.moving_speed(still) is None
    assert dxl.moving_speed(0.6 * dxl.SPEED_RAD_S_PER_UNIT) == 1
    for fast in (100.0, 1e3, -1e300, 1e308):
        assert dxl.moving_speed(fast) == 1023
    for bad in (math.nan, math.inf):
        with pytest.raises(ValueError, match="non-finite"):
            dxl.moving_speed(bad)


READ_ANSWER = dxl.status_packet(3, 0, bytes([0x00, 0x02, 0x10, 0x00]))


@pytest.mark.parametrize(
    ("answer", "fault"),
    [
        (READ_ANSWER, None),
        (b"", dxl.StatusFault.SILENT),
        (READ_ANSWER[:5], dxl.StatusFault.TRUNCATED),
        (READ_ANSWER[:-2], dxl.StatusFault.TRUNCATED),
        (READ_ANSWER[:-1] + bytes([READ_ANSWER[-1] ^ 0x5A]), dxl.StatusFault.CHECKSUM),
        (dxl.status_packet(4, 0, READ_ANSWER[5:-1]), dxl.StatusFault.WRONG_ID),
        (dxl.status_packet(3, 0, READ_ANSWER[5:-2]), dxl.StatusFault.WRONG_LENGTH),
        (dxl.status_packet(3, 0, READ_ANSWER[5:-1] + b"\x00"), dxl.StatusFault.WRONG_LENGTH),
    ],
)
def test_each_fault_of_a_status_packet_is_named(answer: bytes, fault) -> None:
    assert dxl.status_fault(answer, 3, 4) == fault


def test_present_speed_direction_bit() -> None:
    assert dxl.rad_s_of_speed_units(1024 + 300) == -dxl.rad_s_of_speed_units(300)
    assert dxl.signed_speed_units(-dxl.rad_s_of_speed_units(300)) == 1024 + 300
    assert dxl.signed_speed_units(dxl.rad_s_of_speed_units(300)) == 300
    assert dxl.signed_speed_units(-1e-6) == 0
