"""Dynamixel protocol 2.0 packets (protocols/dynamixel_v2.py), against the e-manual's examples
byte for byte and the dynamixel-sdk's own stuffing and CRC."""

from __future__ import annotations

import random

import pytest
from dynamixel_sdk import PacketHandler

from protocols import dynamixel_v2 as dxl
from protocols.dynamixel_v1 import StatusFault
from protocols.dynamixel_v2 import Address, Instruction, PacketParser

PING = bytes.fromhex("FF FF FD 00 01 03 00 01 19 4E")
PING_STATUS = bytes.fromhex("FF FF FD 00 01 07 00 55 00 06 04 26 65 5D")
"""The e-manual's ping of id 1, answered by an XM430-W210 (model 1030, firmware 38)."""
READ = bytes.fromhex("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15")
READ_STATUS = bytes.fromhex("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0")
"""Id 1's Present Position (132, 4 bytes), and its answer: 166."""
WRITE = bytes.fromhex("FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89")
WRITE_STATUS = bytes.fromhex("FF FF FD 00 01 04 00 55 00 A1 0C")
"""Goal Position 512 to id 1, and its answer."""
SYNC_READ = bytes.fromhex("FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA")
SYNC_READ_STATUS_2 = bytes.fromhex("FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE")
SYNC_WRITE = bytes.fromhex(
    "FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87"
)
"""Goal Position 150 to id 1 and 170 to id 2."""
BULK_READ = bytes.fromhex("FF FF FD 00 FE 0D 00 92 01 90 00 02 00 02 92 00 01 00 1A 05")
"""Id 1's 2 bytes at 144 and id 2's byte at 146."""


def test_packets_are_the_e_manual_examples_byte_for_byte() -> None:
    assert dxl.instruction_packet(1, Instruction.PING) == PING
    assert dxl.status_packet(1, 0, dxl.value(1030, 2) + bytes((0x26,))) == PING_STATUS
    assert dxl.read(1, Address.PRESENT_POSITION, 4) == READ
    assert dxl.status_packet(1, 0, dxl.value(166, 4)) == READ_STATUS
    assert dxl.write(1, Address.GOAL_POSITION, dxl.value(512, 4)) == WRITE
    assert dxl.status_packet(1, 0) == WRITE_STATUS
    assert dxl.sync_read(Address.PRESENT_POSITION, 4, (1, 2)) == SYNC_READ
    assert dxl.status_packet(2, 0, dxl.value(2079, 4)) == SYNC_READ_STATUS_2
    data = {1: dxl.value(150, 4), 2: dxl.value(170, 4)}
    assert dxl.sync_write(Address.GOAL_POSITION, 4, data) == SYNC_WRITE
    assert dxl.bulk_read([(1, 144, 2), (2, 146, 1)]) == BULK_READ


def test_crc_is_the_sdks_and_stuffing_is_undone_by_the_parser() -> None:
    """Random parameters rich in FF and FD: the CRC of every packet is the SDK's, and the
    parser gives the parameters back unstuffed."""
    sdk = PacketHandler(2.0)
    rng = random.Random(7)
    for _ in range(300):
        params = bytes(rng.choice((0xFF, 0xFD, 0x00)) for _ in range(rng.randint(0, 12)))
        packet = dxl.instruction_packet(3, Instruction.WRITE, params)
        assert sdk.updateCRC(0, list(packet[:-2]), len(packet) - 2) == dxl.crc16(packet[:-2])
        assert b"\xff\xff\xfd\x00" not in packet[4:]
        (parsed,) = PacketParser().feed(packet)
        assert (parsed.instruction, parsed.params, parsed.crc_ok) == (3, params, True)


def test_stuffing_is_the_e_manuals() -> None:
    assert dxl.stuff(b"\x03\xff\xff\xfd\x01") == b"\x03\xff\xff\xfd\xfd\x01"
    assert dxl.unstuff(b"\x03\xff\xff\xfd\xfd\x01") == b"\x03\xff\xff\xfd\x01"


def test_parser_resyncs_assembles_byte_by_byte_and_reports_a_bad_crc() -> None:
    parser = PacketParser()
    stream = b"\x00\xff\xff\x13" + SYNC_READ + READ_STATUS
    packets = [p for byte in stream for p in parser.feed(bytes((byte,)))]
    assert [(p.id, p.instruction) for p in packets] == [(0xFE, 0x82), (1, dxl.STATUS)]
    assert packets[1].data == dxl.value(166, 4)
    assert parser.skipped_bytes == 4
    bad, good = parser.feed(PING[:-1] + b"\x00" + PING)
    assert (bad.crc_ok, good.crc_ok, parser.bad_checksums) == (False, True, 1)


def test_a_status_fault_is_named() -> None:
    assert dxl.status_fault(READ_STATUS, 1, 4) is None
    assert dxl.status_data(READ_STATUS) == (0, dxl.value(166, 4))
    assert dxl.status_fault(b"", 1, 4) is StatusFault.SILENT
    assert dxl.status_fault(READ_STATUS[:9], 1, 4) is StatusFault.TRUNCATED
    spoiled = READ_STATUS[:-1] + b"\x00"
    assert dxl.status_fault(spoiled, 1, 4) is StatusFault.CHECKSUM
    assert dxl.status_fault(READ_STATUS, 2, 4) is StatusFault.WRONG_ID
    assert dxl.status_fault(READ_STATUS, 1, 2) is StatusFault.WRONG_LENGTH


def test_packets_outside_the_protocol_are_refused() -> None:
    with pytest.raises(dxl.PacketError, match="id 253"):
        dxl.instruction_packet(0xFD, Instruction.PING)
    with pytest.raises(dxl.PacketError, match="at most 1024 expected"):
        dxl.write(1, 0, bytes(1020))
    with pytest.raises(dxl.PacketError, match="3 data bytes, 4 expected"):
        dxl.sync_write(Address.GOAL_POSITION, 4, {1: b"\x00\x02\x00"})
