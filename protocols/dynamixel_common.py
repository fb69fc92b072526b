"""What the framing of both Dynamixel protocols shares: a parser fed a byte stream in pieces of
any size, skipping (and counting) the bytes before a header."""

from __future__ import annotations

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

    def _skip_all_but_header_start(self) -> None:
        """No header in the buffer: skip all of it but a header's beginning at its end."""
        header, buffer = self.header, self._buffer
        keep = next((n for n in range(len(header) - 1, 0, -1) if buffer.endswith(header[:n])), 0)
        self._skip(len(buffer) - keep)

    def _next_packet(self) -> P | None:
        raise NotImplementedError
