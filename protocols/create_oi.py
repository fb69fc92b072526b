"""The iRobot Create 2 Open Interface: the bytes a driver writes and an emulator reads, and the
sensor stream frames an emulator writes and a driver reads. Pure: bytes in, bytes out.

Commands (115200 baud, 8N1): Start 128, Safe 131, Full 132, Drive Direct
``145 Rhi Rlo Lhi Llo`` (signed 16-bit big-endian mm/s, right wheel first, -500..500),
Stream ``148 n id_1 .. id_n``, Pause/Resume Stream ``150 0|1``, Sensors ``142 id`` (the robot
answers the packet's data bytes once; a read, which moves nothing).

Stream frame, sent every 15 ms once requested::

    19 n id_1 data_1 .. id_k data_k checksum,   (19 + n + sum(body) + checksum) mod 256 = 0

with n the number of body bytes (ids and data, not the header, n or the checksum); the spec's
example ``19 5 29 2 25 13 0 163`` holds packet 29 = 0x0219 and packet 13 = 0.

Encoders (packets 43, 44) are 16-bit counts that wrap; one edition of the spec calls them
unsigned, a later one signed. ``encoder_delta`` is right for both. They are not quadrature: the
robot signs the counts by the commanded direction.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Iterable, Sequence
from typing import NamedTuple

START = 128
SAFE = 131
FULL = 132
DRIVE_DIRECT = 145
SENSORS = 142
STREAM = 148
PAUSE_RESUME_STREAM = 150

STREAM_HEADER = 19
BUMPS_AND_WHEEL_DROPS = 7
VIRTUAL_WALL = 13
CLIFF_FRONT_LEFT_SIGNAL = 29
LEFT_ENCODER = 43
RIGHT_ENCODER = 44
BATTERY_CHARGE = 25
"""mAh."""
BATTERY_CAPACITY = 26
"""mAh."""
OI_MODE = 35
OI_MODES = ("off", "passive", "safe", "full")
"""The names of packet 35's values 0..3."""

PACKET_LENGTHS: dict[int, int] = {
    BUMPS_AND_WHEEL_DROPS: 1,
    VIRTUAL_WALL: 1,
    CLIFF_FRONT_LEFT_SIGNAL: 2,
    LEFT_ENCODER: 2,
    RIGHT_ENCODER: 2,
    BATTERY_CHARGE: 2,
    BATTERY_CAPACITY: 2,
    OI_MODE: 1,
}
"""Data bytes of each sensor packet this module decodes; every one is unsigned, big-endian."""

BAUD = 115200
STREAM_PERIOD_S = 0.015
WHEEL_SPEED_LIMIT_MM_S = 500
COUNTS_PER_TURN = 508.8
"""Encoder counts per wheel turn."""

_ENCODER_RANGE = 1 << 16


def drive_direct(right_mm_s: int, left_mm_s: int) -> bytes:
    """Drive Direct: ``145 Rhi Rlo Lhi Llo``, each speed clamped to +-500 mm/s."""
    return struct.pack(
        ">Bhh", DRIVE_DIRECT, clamp_wheel_speed(right_mm_s), clamp_wheel_speed(left_mm_s)
    )


def parse_drive_direct(payload4: bytes) -> tuple[int, int]:
    """(right, left) mm/s from the 4 data bytes after the 145 opcode (not clamped)."""
    if len(payload4) != 4:
        raise ValueError(f"Drive Direct carries 4 data bytes, got {len(payload4)}")
    right, left = struct.unpack(">hh", payload4)
    return right, left


def clamp_wheel_speed(mm_s: int) -> int:
    """A wheel speed (mm/s) clamped to the robot's +-500."""
    return max(-WHEEL_SPEED_LIMIT_MM_S, min(WHEEL_SPEED_LIMIT_MM_S, int(mm_s)))


def stream_request(packet_ids: Iterable[int]) -> bytes:
    """Stream: ``148 n id_1 .. id_n``."""
    ids = list(packet_ids)
    return bytes([STREAM, len(ids), *ids])


def sensors(packet_id: int) -> bytes:
    """Sensors: ``142 id``, answered by the packet's data bytes (``packet_data``)."""
    _packet_length(packet_id)
    return bytes([SENSORS, packet_id])


def pause_resume(on: bool) -> bytes:
    """Pause/Resume Stream: ``150 1`` resumes, ``150 0`` pauses."""
    return bytes([PAUSE_RESUME_STREAM, 1 if on else 0])


def packet_data(packet_id: int, value: int) -> bytes:
    """The data bytes of a sensor packet: ``value`` wrapped to the packet's unsigned width."""
    length = _packet_length(packet_id)
    return (value % (1 << (8 * length))).to_bytes(length, "big")


def stream_frame(packets: dict[int, bytes]) -> bytes:
    """``19 n id data .. checksum`` for ``packets`` (packet id -> data bytes), in dict order."""
    body = bytearray()
    for packet_id, data in packets.items():
        if len(data) != _packet_length(packet_id):
            raise ValueError(
                f"packet {packet_id} carries {_packet_length(packet_id)} data bytes, "
                f"got {len(data)}"
            )
        body.append(packet_id)
        body += data
    frame = bytes([STREAM_HEADER, len(body)]) + body
    return frame + bytes([-sum(frame) & 0xFF])


def _packet_length(packet_id: int) -> int:
    try:
        return PACKET_LENGTHS[packet_id]
    except KeyError:
        raise ValueError(
            f"unsupported sensor packet {packet_id}, expected one of {sorted(PACKET_LENGTHS)}"
        ) from None


class StreamFrame(NamedTuple):
    """A decoded stream frame: packet id -> unsigned value, and how many frames the parser
    refused since the previous good one (each one stream period the robot went on moving)."""

    packets: dict[int, int]
    lost: int


class StreamParser:
    """Splits a byte stream into stream frames and decodes their packets.

    ``feed`` returns one ``StreamFrame`` per complete frame whose checksum holds and whose body
    is a sequence of packets of ``PACKET_LENGTHS``. It never raises.
    Counters: ``resyncs`` bytes skipped while looking for a header 19, ``bad_checksums`` frames
    whose checksum failed, ``bad_frames`` frames with a good checksum but an unknown packet id
    or a body that does not split into whole packets. After a bad frame the parser drops only
    its 19 and looks for the next one, so a 19 inside garbage costs one frame, not a lock.

    Given the ``packet_ids`` a driver asked for (``stream_request``), a frame must carry
    exactly those, in that order: a 19 whose n is not their length is dropped at once, so a
    stray ``19 255`` costs the bytes up to the next frame instead of 258 bytes of waiting, and
    a frame of other packets is a bad frame.
    """

    def __init__(self, packet_ids: Sequence[int] | None = None) -> None:
        self._buffer = bytearray()
        self._ids = None if packet_ids is None else tuple(packet_ids)
        self._body_length = (
            None if self._ids is None else sum(1 + _packet_length(i) for i in self._ids)
        )
        self.resyncs = 0
        self.bad_checksums = 0
        self.bad_frames = 0
        self._refused_at_last_frame = 0

    def feed(self, data: bytes) -> list[StreamFrame]:
        self._buffer += data
        frames: list[StreamFrame] = []
        while self._skip_to_header() and len(self._buffer) >= 2:
            if self._body_length is not None and self._buffer[1] != self._body_length:
                self.resyncs += 1
                del self._buffer[0]
                continue
            end = self._buffer[1] + 3
            if len(self._buffer) < end:
                break
            frame = bytes(self._buffer[:end])
            packets = self._decode(frame)
            if packets is None:
                del self._buffer[0]
            else:
                refused = self.bad_checksums + self.bad_frames
                frames.append(StreamFrame(packets, refused - self._refused_at_last_frame))
                self._refused_at_last_frame = refused
                del self._buffer[:end]
        return frames

    def _skip_to_header(self) -> bool:
        """Drop bytes before the next 19; False if none is buffered."""
        start = self._buffer.find(STREAM_HEADER)
        skipped = len(self._buffer) if start < 0 else start
        self.resyncs += skipped
        del self._buffer[:skipped]
        return start >= 0

    def _decode(self, frame: bytes) -> dict[int, int] | None:
        if sum(frame) & 0xFF:
            self.bad_checksums += 1
            return None
        body = frame[2:-1]
        packets: dict[int, int] = {}
        i = 0
        while i < len(body):
            length = PACKET_LENGTHS.get(body[i])
            if length is None or i + 1 + length > len(body):
                self.bad_frames += 1
                return None
            packets[body[i]] = int.from_bytes(body[i + 1 : i + 1 + length], "big")
            i += 1 + length
        if self._ids is not None and tuple(packets) != self._ids:
            self.bad_frames += 1
            return None
        return packets


def encoder_delta(new: int, old: int) -> int:
    """Signed change of a 16-bit encoder count across a rollover, for signed or unsigned readings:
    d = (new - old) mod 2^16, minus 2^16 when d >= 2^15."""
    d = (new - old) & 0xFFFF
    return d - _ENCODER_RANGE if d >= 0x8000 else d


def mm_per_count(wheel_diameter_m: float) -> float:
    """Distance (mm) a wheel rolls per encoder count: pi d 1000 / 508.8 (d in m)."""
    return math.pi * wheel_diameter_m * 1000.0 / COUNTS_PER_TURN
