"""Dynamixel protocol 2.0 (X-series: XM430, XL430): instruction and status packets, the X-series
control table. Pure: bytes in, bytes out.

Instruction packet and status packet::

    FF FF FD 00 id len_l len_h instruction param_1 .. param_n crc_l crc_h
    FF FF FD 00 id len_l len_h 55 error    param_1 .. param_n crc_l crc_h

with length = n + 3 (instruction and CRC, the error counted as a parameter of the status) and
the CRC-16 of the e-manual (polynomial 0x8005, no reflection, initial 0) over everything before
it. Byte stuffing: within instruction and parameters, ``FF FF FD`` is sent ``FF FF FD FD`` (the
length counts the stuffed bytes), so that a header never appears inside a packet. Broadcast id
0xFE reaches every servo; only Ping, Sync Read and Bulk Read get answers to it (one status per
servo). Multi-byte values are little-endian. The e-manual's read of id 1's Present Position is
``FF FF FD 00 01 07 00 02 84 00 04 00 1D 15``.

The status error byte: bit 7 is the alert (a hardware error: read Hardware Error Status, 70),
bits 0..6 the error number of the instruction (``StatusError``).

The values' units (angles and speeds in and out of the table) are in
``protocols.x_series_units``.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from protocols.dynamixel_common import FrameParser
from protocols.dynamixel_v1 import StatusFault

HEADER = b"\xff\xff\xfd\x00"
BROADCAST_ID = 0xFE
STATUS = 0x55
"""The instruction byte of a status packet."""
MAX_PACKET_BYTES = 1024
"""Longest packet, header and CRC included (the dynamixel-sdk's TXPACKET_MAX_LEN)."""
_PREFIX = 7
"""Header, id and length: the bytes before the instruction."""
_MIN_LENGTH = 3
MIN_STATUS_BYTES = _PREFIX + 4
"""The shortest status packet: header, id, length, 55, error and CRC."""


class Instruction(enum.IntEnum):
    PING = 0x01
    READ = 0x02
    WRITE = 0x03
    REG_WRITE = 0x04
    ACTION = 0x05
    FACTORY_RESET = 0x06
    REBOOT = 0x08
    SYNC_READ = 0x82
    SYNC_WRITE = 0x83
    BULK_READ = 0x92
    BULK_WRITE = 0x93


class StatusError(enum.IntEnum):
    """The error number of a status packet (its error byte without the alert bit)."""

    NONE = 0
    RESULT_FAIL = 1
    INSTRUCTION = 2
    CRC = 3
    DATA_RANGE = 4
    DATA_LENGTH = 5
    DATA_LIMIT = 6
    ACCESS = 7


ALERT = 0x80
"""Bit 7 of the error byte: the servo has a hardware error (Hardware Error Status)."""


class HardwareError(enum.IntFlag):
    """Bits of Hardware Error Status (70)."""

    INPUT_VOLTAGE = 1
    OVERHEATING = 4
    MOTOR_ENCODER = 8
    ELECTRICAL_SHOCK = 16
    OVERLOAD = 32


class Address(enum.IntEnum):
    """The X-series (XM430, XL430) control table: EEPROM below 64 (written with torque off
    only), RAM from 64."""

    MODEL_NUMBER = 0
    FIRMWARE_VERSION = 6
    ID = 7
    BAUD_RATE = 8
    RETURN_DELAY = 9
    """2 us per unit."""
    OPERATING_MODE = 11
    MOVING_THRESHOLD = 24
    VELOCITY_LIMIT = 44
    MAX_POSITION_LIMIT = 48
    MIN_POSITION_LIMIT = 52
    SHUTDOWN = 63
    TORQUE_ENABLE = 64
    STATUS_RETURN_LEVEL = 68
    HARDWARE_ERROR_STATUS = 70
    GOAL_VELOCITY = 104
    PROFILE_VELOCITY = 112
    GOAL_POSITION = 116
    MOVING = 122
    PRESENT_VELOCITY = 128
    PRESENT_POSITION = 132
    PRESENT_TEMPERATURE = 146


SIZES: dict[Address, int] = {
    Address.MODEL_NUMBER: 2,
    Address.MOVING_THRESHOLD: 4,
    Address.VELOCITY_LIMIT: 4,
    Address.MAX_POSITION_LIMIT: 4,
    Address.MIN_POSITION_LIMIT: 4,
    Address.GOAL_VELOCITY: 4,
    Address.PROFILE_VELOCITY: 4,
    Address.GOAL_POSITION: 4,
    Address.PRESENT_VELOCITY: 4,
    Address.PRESENT_POSITION: 4,
}
"""Bytes of each entry of more than one byte."""
EEPROM_END = Address.TORQUE_ENABLE
"""Addresses below it are written only with torque off (else the Access error)."""
SIGNED = frozenset((Address.GOAL_VELOCITY, Address.PRESENT_VELOCITY, Address.PRESENT_POSITION))


class OperatingMode(enum.IntEnum):
    VELOCITY = 1
    POSITION = 3


class PacketError(ValueError):
    """A packet that protocol 2.0 cannot carry."""


@dataclass(frozen=True)
class Packet:
    """A framed packet, parameters unstuffed. A status packet has instruction ``STATUS`` and
    its error byte first in ``params``; a packet whose CRC did not match has ``crc_ok`` False."""

    id: int
    instruction: int
    params: bytes
    crc_ok: bool = True

    @property
    def error(self) -> int:
        """A status packet's error byte (alert bit and error number)."""
        return self.params[0] if self.params else 0

    @property
    def data(self) -> bytes:
        """A status packet's parameters after the error byte."""
        return self.params[1:]


_CRC_TABLE = []
for _byte in range(256):
    _crc = _byte << 8
    for _ in range(8):
        _crc = (_crc << 1) ^ 0x8005 if _crc & 0x8000 else _crc << 1
    _CRC_TABLE.append(_crc & 0xFFFF)


def crc16(data: Iterable[int]) -> int:
    """The e-manual's CRC-16 (polynomial 0x8005, initial 0, no reflection, no final XOR)."""
    crc = 0
    for byte in data:
        crc = ((crc << 8) ^ _CRC_TABLE[((crc >> 8) ^ byte) & 0xFF]) & 0xFFFF
    return crc


def stuff(body: bytes) -> bytes:
    """Instruction and parameters with an FD added after every ``FF FF FD``."""
    out = bytearray()
    for byte in body:
        out.append(byte)
        if byte == 0xFD and out[-3:-1] == b"\xff\xff":
            out.append(0xFD)
    return bytes(out)


def unstuff(body: bytes) -> bytes:
    """``stuff`` undone: the FD after every ``FF FF FD`` dropped."""
    out = bytearray()
    index = 0
    while index < len(body):
        out.append(body[index])
        stuffed = body[index + 1 : index + 2] == b"\xfd"
        if body[index] == 0xFD and out[-3:-1] == b"\xff\xff" and stuffed:
            index += 1
        index += 1
    return bytes(out)


def _packet(servo_id: int, body: bytes) -> bytes:
    if not 0 <= servo_id <= BROADCAST_ID or servo_id == 0xFD:
        raise PacketError(f"id {servo_id} outside 0..252 and 254")
    stuffed = stuff(body)
    if len(stuffed) + _PREFIX + 2 > MAX_PACKET_BYTES:
        raise PacketError(
            f"{len(body) - 1} parameters make a {len(stuffed) + _PREFIX + 2}-byte packet, "
            f"at most {MAX_PACKET_BYTES} expected"
        )
    frame = HEADER + bytes((servo_id,)) + (len(stuffed) + 2).to_bytes(2, "little") + stuffed
    return frame + crc16(frame).to_bytes(2, "little")


def instruction_packet(servo_id: int, instruction: int, params: bytes = b"") -> bytes:
    """An instruction packet, stuffed, with its CRC; PacketError when it cannot be."""
    return _packet(servo_id, bytes((instruction,)) + bytes(params))


def status_packet(servo_id: int, error: int, params: bytes = b"") -> bytes:
    """A status packet (error byte, then ``params``), stuffed, with its CRC."""
    return _packet(servo_id, bytes((STATUS, error)) + bytes(params))


def value(number: int, size: int) -> bytes:
    """A control table value of ``size`` bytes, low byte first (negative: two's complement)."""
    return (number & ((1 << 8 * size) - 1)).to_bytes(size, "little")


def signed(data: bytes) -> int:
    return int.from_bytes(data, "little", signed=True)


def read(servo_id: int, address: int, length: int) -> bytes:
    return instruction_packet(servo_id, Instruction.READ, value(address, 2) + value(length, 2))


def write(servo_id: int, address: int, data: bytes) -> bytes:
    return instruction_packet(servo_id, Instruction.WRITE, value(address, 2) + data)


def sync_read(address: int, length: int, ids: Sequence[int]) -> bytes:
    """A Sync Read of ``length`` bytes at ``address`` from each of ``ids`` (answered in order)."""
    params = value(address, 2) + value(length, 2) + bytes(ids)
    return instruction_packet(BROADCAST_ID, Instruction.SYNC_READ, params)


def sync_write(address: int, length: int, data: Mapping[int, bytes]) -> bytes:
    """A Sync Write of ``length`` bytes at ``address`` to each id of ``data``."""
    params = bytearray(value(address, 2) + value(length, 2))
    for servo_id, values in data.items():
        if len(values) != length:
            raise PacketError(f"servo {servo_id}: {len(values)} data bytes, {length} expected")
        params += bytes((servo_id,)) + values
    return instruction_packet(BROADCAST_ID, Instruction.SYNC_WRITE, bytes(params))


def bulk_read(reads: Sequence[tuple[int, int, int]]) -> bytes:
    """A Bulk Read of (id, address, length) each (answered in order)."""
    params = b"".join(bytes((i,)) + value(a, 2) + value(n, 2) for i, a, n in reads)
    return instruction_packet(BROADCAST_ID, Instruction.BULK_READ, params)


def bulk_write(writes: Sequence[tuple[int, int, bytes]]) -> bytes:
    """A Bulk Write of (id, address, data) each."""
    params = b"".join(bytes((i,)) + value(a, 2) + value(len(d), 2) + d for i, a, d in writes)
    return instruction_packet(BROADCAST_ID, Instruction.BULK_WRITE, params)


def blocks(params: bytes, length: int) -> dict[int, bytes] | None:
    """A Sync Write's ``id, data`` blocks of ``length`` bytes by id; None when malformed."""
    step = length + 1
    if length < 1 or len(params) % step:
        return None
    return {params[i]: params[i + 1 : i + step] for i in range(0, len(params), step)}


def bulk_blocks(params: bytes, with_data: bool) -> list[tuple[int, int, int, bytes]] | None:
    """A Bulk Read's (or, ``with_data``, Bulk Write's) (id, address, length, data) blocks;
    None when malformed."""
    out, index = [], 0
    while index < len(params):
        if index + 5 > len(params):
            return None
        servo_id, address = params[index], int.from_bytes(params[index + 1 : index + 3], "little")
        length = int.from_bytes(params[index + 3 : index + 5], "little")
        data = params[index + 5 : index + 5 + length] if with_data else b""
        if with_data and len(data) != length:
            return None
        out.append((servo_id, address, length, data))
        index += 5 + len(data)
    return out


def status_fault(answer: bytes, servo_id: int, params: int) -> StatusFault | None:
    """What is wrong with ``answer``, the bytes from the header on that came back from
    ``servo_id`` for an instruction asking for ``params`` parameter bytes; None when it is that
    servo's whole status packet with a good CRC."""
    if not answer:
        return StatusFault.SILENT
    if len(answer) < MIN_STATUS_BYTES or answer[:4] != HEADER:
        return StatusFault.TRUNCATED
    end = _PREFIX + int.from_bytes(answer[5:7], "little")
    if len(answer) < end:
        return StatusFault.TRUNCATED
    if crc16(answer[: end - 2]) != int.from_bytes(answer[end - 2 : end], "little"):
        return StatusFault.CHECKSUM
    if answer[4] != servo_id:
        return StatusFault.WRONG_ID
    body = unstuff(answer[_PREFIX : end - 2])
    if body[0] != STATUS or len(body) - 2 != params:
        return StatusFault.WRONG_LENGTH
    return None


def status_data(answer: bytes) -> tuple[int, bytes]:
    """The error byte and parameters of a whole status packet (``status_fault`` None)."""
    end = _PREFIX + int.from_bytes(answer[5:7], "little")
    body = unstuff(answer[_PREFIX : end - 2])
    return body[1], body[2:]


def packet_end(buffer: bytes) -> int | None:
    """How many bytes the packet at the start of ``buffer`` takes; None until its length is
    there."""
    if len(buffer) < _PREFIX:
        return None
    return _PREFIX + int.from_bytes(buffer[5:7], "little")


class PacketParser(FrameParser[Packet]):
    """Frames packets from a byte stream fed in pieces of any size; never raises.

    A frame starts at ``FF FF FD 00`` followed by an id other than 0xFD and 0xFF and a length
    of 3 or more that fits ``MAX_PACKET_BYTES``. Bytes before a frame are skipped and counted
    in ``skipped_bytes``. A frame whose CRC does not match is returned (``crc_ok`` False, as a
    servo answers it with the CRC error), counted in ``bad_checksums``, and only its header is
    consumed: the rest is scanned again.
    """

    header = HEADER

    def _next_packet(self) -> Packet | None:
        buffer = self._buffer
        while True:
            if not self._to_header():
                return None
            end = packet_end(buffer)
            if end is None:
                return None
            if buffer[4] in (0xFD, 0xFF) or not _MIN_LENGTH <= end - _PREFIX <= (
                MAX_PACKET_BYTES - _PREFIX
            ):
                self._skip(4)
                continue
            if len(buffer) < end:
                return None
            body = unstuff(bytes(buffer[_PREFIX : end - 2]))
            ok = crc16(buffer[: end - 2]) == int.from_bytes(buffer[end - 2 : end], "little")
            packet = Packet(buffer[4], body[0], body[1:], crc_ok=ok)
            if ok:
                del buffer[:end]
            else:
                self.bad_checksums += 1
                del buffer[:4]
            return packet
