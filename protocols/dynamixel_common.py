"""What both Dynamixel protocols share: a parser fed a byte stream in pieces of any size,
skipping (and counting) the bytes before a header; a servo model's position scale; a speed
limit's value."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Generic, TypeVar

P = TypeVar("P")


class FrameParser(Generic[P]):
    """Frames packets from a byte stream; a protocol gives its ``header`` and its
    ``_next_packet`` (the first whole frame in the buffer, consumed; None until one is
    complete). ``skipped_bytes`` counts the bytes skipped before frames, ``bad_checksums`` the
    frames whose checksum did not match."""

    header: bytes

    def __init__(self) -> None:
        self._buffer = bytearray()
        self.skipped_bytes = 0
        self.bad_checksums = 0

    def feed(self, data: bytes) -> list[P]:
        self._buffer += data
        packets: list[P] = []
        while (packet := self._next_packet()) is not None:
            packets.append(packet)
        return packets

    def _skip(self, count: int) -> None:
        del self._buffer[:count]
        self.skipped_bytes += count

    def _to_header(self) -> bool:
        """Skip to the buffer's first header; False when there is none (then all of it is
        skipped but a header's beginning at its end)."""
        header, buffer = self.header, self._buffer
        start = buffer.find(header)
        if start < 0:
            prefixes = range(len(header) - 1, 0, -1)
            keep = next((n for n in prefixes if buffer.endswith(header[:n])), 0)
            self._skip(len(buffer) - keep)
            return False
        self._skip(start)
        return True

    def _next_packet(self) -> P | None:
        raise NotImplementedError


@dataclass(frozen=True)
class PositionScale:
    """A servo model's position values: ``center`` at 0 rad, ``units_per_rad``, 0..``max_units``;
    a goal angle is clamped to +-``clamp_rad`` before it is rounded."""

    center: int
    units_per_rad: float
    max_units: int
    clamp_rad: float

    def of_angle(self, angle_rad: float) -> float:
        """The Goal Position of an angle, before rounding."""
        return self.center + angle_rad * self.units_per_rad

    def units(self, angle_rad: float) -> int:
        """Goal Position of a joint angle (rad, 0 at the centre), clamped to 0..``max_units``;
        ValueError for a non-finite angle."""
        if not math.isfinite(angle_rad):
            raise ValueError(f"no position for a non-finite angle {angle_rad}")
        units = round(self.of_angle(min(max(angle_rad, -self.clamp_rad), self.clamp_rad)))
        return min(max(units, 0), self.max_units)

    def angle(self, units: int) -> float:
        """Joint angle (rad) of a Present or Goal Position."""
        return (units - self.center) / self.units_per_rad


def speed_limit(rad_s: float, rad_s_per_unit: float, max_units: int, name: str) -> int | None:
    """The speed limit value (``name``) of a speed magnitude, at most ``max_units``; None when
    it rounds to 0 (which means no limit, not stop: a joint that slow must hold). ValueError
    for a non-finite speed."""
    if not math.isfinite(rad_s):
        raise ValueError(f"no {name} for a non-finite speed {rad_s}")
    return round(min(abs(rad_s), max_units * rad_s_per_unit) / rad_s_per_unit) or None
