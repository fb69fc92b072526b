"""Dynamixel protocol 1.0 (AX-18A): the instruction packets a driver writes and a servo reads,
the status packets a servo answers, and the AX-18A's units. Pure: bytes in, bytes out.

Instruction packet and status packet::

    FF FF id length instruction param_1 .. param_n checksum
    FF FF id length error       param_1 .. param_n checksum

with length = n + 2 and checksum = ~(id + length + instruction_or_error + sum(params)) & 0xFF.
Broadcast id 0xFE reaches every servo and none answers. Sync Write (0x83, broadcast) carries
``address, data_length`` then ``id, data`` for each servo; the e-manual's example, goal
position and moving speed of ids 0 and 1, is
``FF FF FE 0E 83 1E 04 00 10 00 50 01 01 20 02 60 03 67``. Multi-byte values are little-endian.

Units (AX-18A): position 0..1023 over 300 degrees, 512 the centre (0 rad here), angles counter
clockwise positive; speed about 0.111 rpm per unit. Moving Speed 1..1023 is a magnitude and 0
means full speed without speed control, not stop. Present Speed and Present Load carry the
magnitude in bits 0..9 and the direction in bit 10, set for clockwise (negative).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from protocols.dynamixel_common import FrameParser, PositionScale, speed_limit

HEADER = b"\xff\xff"
BROADCAST_ID = 0xFE
MAX_PACKET_BYTES = 250
"""Longest packet, header and checksum included (the dynamixel-sdk's TXPACKET_MAX_LEN)."""
_MIN_LENGTH = 2
_MAX_LENGTH = MAX_PACKET_BYTES - 4


class Instruction(enum.IntEnum):
    PING = 0x01
    READ = 0x02
    WRITE = 0x03
    REG_WRITE = 0x04
    ACTION = 0x05
    RESET = 0x06
    SYNC_WRITE = 0x83


class StatusError(enum.IntFlag):
    """Bits of a status packet's error byte."""

    INPUT_VOLTAGE = 1
    ANGLE_LIMIT = 2
    OVERHEATING = 4
    RANGE = 8
    CHECKSUM = 16
    OVERLOAD = 32
    INSTRUCTION = 64


class Address(enum.IntEnum):
    """AX-18A control table addresses; words are two bytes, low byte first."""

    MODEL_NUMBER = 0
    ID = 3
    BAUD_RATE = 4
    RETURN_DELAY = 5
    """2 us per unit."""
    CW_ANGLE_LIMIT = 6
    CCW_ANGLE_LIMIT = 8
    STATUS_RETURN_LEVEL = 16
    TORQUE_ENABLE = 24
    CW_COMPLIANCE_MARGIN = 26
    GOAL_POSITION = 30
    MOVING_SPEED = 32
    PRESENT_POSITION = 36
    PRESENT_SPEED = 38
    PRESENT_LOAD = 40
    REGISTERED = 44
    MOVING = 46


RETURN_DELAY_US_PER_UNIT = 2.0
POSITION_CENTER = 512
POSITION_MAX = 1023
POSITION_UNITS_PER_RAD = 1024 / math.radians(300.0)
"""1024 steps over 300 degrees (0.293 degree each), so that 512 is the centre exactly."""
SPEED_MAX = 1023
SPEED_RAD_S_PER_UNIT = 0.111 * 2.0 * math.pi / 60.0
"""0.111 rpm per unit."""
_HALF_SPAN = POSITION_MAX / POSITION_UNITS_PER_RAD
"""An angle bound wider than the servo's travel, so that rounding never meets a huge float."""
DIRECTION_BIT = 0x400
"""Bit 10 of Present Speed and Present Load: set for clockwise (negative)."""


class PacketError(ValueError):
    """A packet that protocol 1.0 cannot carry."""


@dataclass(frozen=True)
class Packet:
    """A framed packet. ``code`` is the instruction of an instruction packet and the error byte
    of a status packet; a packet whose checksum did not match has ``checksum_ok`` False."""

    id: int
    code: int
    params: bytes
    checksum_ok: bool = True

    @property
    def instruction(self) -> int:
        return self.code

    @property
    def error(self) -> StatusError:
        return StatusError(self.code & 0x7F)


class StatusFault(enum.StrEnum):
    """What is wrong with the answer to an instruction that expects a status packet."""

    SILENT = "silent"
    """No byte came back before the timeout."""
    TRUNCATED = "truncated"
    """Fewer bytes came back than the packet's length says."""
    CHECKSUM = "checksum"
    WRONG_ID = "wrong_id"
    """A whole status packet, from another servo."""
    WRONG_LENGTH = "wrong_length"
    """A whole status packet of this servo that carries other than the parameters asked for."""


def status_fault(answer: bytes, servo_id: int, params: int) -> StatusFault | None:
    """What is wrong with ``answer``, the bytes from ``FF FF`` on that came back from
    ``servo_id`` for an instruction asking for ``params`` parameter bytes; None when it is
    that servo's whole status packet with a good checksum."""
    if not answer:
        return StatusFault.SILENT
    if len(answer) < 6 or answer[:2] != HEADER or len(answer) < answer[3] + 4:
        return StatusFault.TRUNCATED
    packet = answer[: answer[3] + 4]
    if checksum(packet[2:-1]) != packet[-1]:
        return StatusFault.CHECKSUM
    if packet[2] != servo_id:
        return StatusFault.WRONG_ID
    if packet[3] - _MIN_LENGTH != params:
        return StatusFault.WRONG_LENGTH
    return None


def checksum(body: Iterable[int]) -> int:
    """~(id + length + instruction_or_error + params) & 0xFF over ``body`` (no header)."""
    return ~sum(body) & 0xFF


def _packet(servo_id: int, code: int, params: bytes) -> bytes:
    if not 0 <= servo_id <= BROADCAST_ID:
        raise PacketError(f"id {servo_id} outside 0..{BROADCAST_ID}")
    if not 0 <= code <= 0xFF:
        raise PacketError(f"instruction or error {code} is not one byte")
    length = len(params) + _MIN_LENGTH
    if length > _MAX_LENGTH:
        raise PacketError(
            f"{len(params)} parameters make a {length + 4}-byte packet, at most "
            f"{MAX_PACKET_BYTES} expected"
        )
    body = bytes((servo_id, length, code)) + params
    return HEADER + body + bytes((checksum(body),))


def instruction_packet(servo_id: int, instruction: int, params: bytes = b"") -> bytes:
    """``FF FF id length instruction params checksum``; raises PacketError when it cannot be."""
    return _packet(servo_id, instruction, bytes(params))


def status_packet(servo_id: int, error: int, params: bytes = b"") -> bytes:
    """``FF FF id length error params checksum``; raises PacketError when it cannot be."""
    return _packet(servo_id, error, bytes(params))


def sync_write(address: int, data_length: int, data: Mapping[int, bytes]) -> bytes:
    """A broadcast Sync Write of ``data_length`` bytes at ``address`` to each id of ``data``."""
    params = bytearray((address, data_length))
    for servo_id, values in data.items():
        if len(values) != data_length:
            raise PacketError(f"servo {servo_id}: {len(values)} data bytes, {data_length} expected")
        params.append(servo_id)
        params += values
    return instruction_packet(BROADCAST_ID, Instruction.SYNC_WRITE, bytes(params))


def word(value: int) -> bytes:
    """A control table word, low byte first."""
    return (value & 0xFFFF).to_bytes(2, "little")


class PacketParser(FrameParser[Packet]):
    """Frames packets from a byte stream fed in pieces of any size; never raises.

    A frame starts at ``FF FF`` followed by an id other than 0xFF and a length 2..246. Bytes
    before a frame are skipped and counted in ``skipped_bytes``. A frame whose checksum does not
    match is returned (``checksum_ok`` False, as a servo answers it with the checksum error),
    counted in ``bad_checksums``, and only its header is consumed: the rest is scanned again, so
    a packet that a corrupt length had swallowed is still found.
    """

    header = HEADER

    def _next_packet(self) -> Packet | None:
        """The first whole frame in the buffer, consuming it; None until one is complete."""
        buffer = self._buffer
        while True:
            if not self._to_header():
                return None
            if len(buffer) < 4:
                return None
            if buffer[2] == 0xFF:
                self._skip(1)
                continue
            length = buffer[3]
            if not _MIN_LENGTH <= length <= _MAX_LENGTH:
                self._skip(2)
                continue
            end = length + 4
            if len(buffer) < end:
                return None
            packet = Packet(buffer[2], buffer[4], bytes(buffer[5 : end - 1]))
            if checksum(buffer[2 : end - 1]) == buffer[end - 1]:
                del buffer[:end]
                return packet
            self.bad_checksums += 1
            del buffer[:2]
            return Packet(packet.id, packet.code, packet.params, checksum_ok=False)


_POSITIONS = PositionScale(POSITION_CENTER, POSITION_UNITS_PER_RAD, POSITION_MAX, _HALF_SPAN)
position_units = _POSITIONS.units
"""Goal Position of a joint angle (rad, 0 at the centre), clamped to 0..1023."""
position_of_angle = _POSITIONS.of_angle
"""512 + angle * 1024 / 300 degrees: the Goal Position of an angle, before rounding."""
angle_of_units = _POSITIONS.angle


def moving_speed(rad_s: float) -> int | None:
    """Moving Speed of a speed magnitude: round(|rad_s| / 0.0116), at most 1023; None when
    that is 0, for Moving Speed 0 means full speed: a joint that slow must hold. ValueError
    for a non-finite speed."""
    return speed_limit(rad_s, SPEED_RAD_S_PER_UNIT, SPEED_MAX, "moving speed")


def signed_speed_units(rad_s: float) -> int:
    """Present Speed of a joint velocity (rad/s): magnitude in bits 0..9, bit 10 if negative."""
    magnitude = min(round(abs(rad_s) / SPEED_RAD_S_PER_UNIT), SPEED_MAX)
    return magnitude | DIRECTION_BIT if rad_s < 0 and magnitude else magnitude


def rad_s_of_speed_units(units: int) -> float:
    """Joint velocity (rad/s) of a Present Speed (bit 10 set: clockwise, negative) or of a
    Moving Speed magnitude (0 there means full speed, which this does not know)."""
    magnitude = (units & SPEED_MAX) * SPEED_RAD_S_PER_UNIT
    return -magnitude if units & DIRECTION_BIT else magnitude
