"""An emulated iRobot Create 2 on a pseudo-terminal: a driver opens ``port`` (or the symlink)
with pyserial as it would the robot's USB serial cable, and the emulator answers as the robot.

The OI modes: Off until Start (128), which sets Passive (and stops the wheels); Safe (131) and
Full (132) from any started mode. Drive Direct (145) acts in Safe and Full only, clamps each
wheel to +-500 mm/s and sets the backend's wheel speeds (m/s) until the next command: the real
robot has no command timeout. Stream (148 n ids) sends a frame of the requested packets every
15 ms, encoders (43, 44) as counts mod 2^16; Pause/Resume Stream (150 0|1); Sensors (142 id)
answers the OI mode (35) and the battery's charge and capacity (25, 26: ``battery_mah``) once.
Commands other than Start are ignored while Off; ``opcodes`` counts the commands received by
opcode. Bytes that start no known command are counted and skipped; packets
other than the encoders are counted and left out of the frames. Safe mode's cliff and wheel-drop
reflexes are not emulated.

The backend is the world the robot drives in (``sim2d`` or a test double); the emulator calls it
from its two threads under one lock, so the backend need not be thread-safe.
"""

from __future__ import annotations

import enum
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Protocol

from protocols import create_oi as oi
from sim2d.devices.pty_link import SerialDevice

_ENCODERS = (oi.LEFT_ENCODER, oi.RIGHT_ENCODER)


class WheelBackend(Protocol):
    def set_wheel_speeds(self, left: float, right: float) -> None:
        """Commanded wheel speeds, m/s."""

    def encoder_counts(self) -> tuple[int, int]:
        """Cumulative (left, right) encoder counts, unwrapped."""


class Mode(enum.Enum):
    OFF = "off"
    PASSIVE = "passive"
    SAFE = "safe"
    FULL = "full"


_FIXED_DATA_LENGTHS: dict[int, int] = {
    oi.START: 0,
    oi.SAFE: 0,
    oi.FULL: 0,
    oi.DRIVE_DIRECT: 4,
    oi.PAUSE_RESUME_STREAM: 1,
    oi.SENSORS: 1,
}
"""Data bytes after each opcode the emulator knows, but Stream's, which carries 1 + n."""
_DRIVING_MODES = (Mode.SAFE, Mode.FULL)


def _data_length(pending: bytes) -> int | None:
    """Data bytes of the command ``pending`` begins with a known opcode; None while unknown."""
    if pending[0] == oi.STREAM:
        return 1 + pending[1] if len(pending) >= 2 else None
    return _FIXED_DATA_LENGTHS[pending[0]]


class Create2Emulator(SerialDevice):
    """The robot end of a pty. ``port`` is the slave's path, which a driver opens; ``mode`` the
    OI mode; ``counters`` counts commands executed and ignored, bad bytes (no known opcode),
    unsupported stream packets, the stream's periods (a frame sent in each while streaming),
    frames sent and output bytes dropped while nobody read."""

    def __init__(
        self,
        backend: WheelBackend,
        link: Path | None = None,
        battery_mah: tuple[int, int] = (2400, 3000),
    ) -> None:
        self._backend = backend
        self.battery_mah = battery_mah
        """The battery's charge and capacity (mAh)."""
        self.opcodes: Counter[int] = Counter()
        super().__init__(
            link,
            (
                "commands",
                "ignored_commands",
                "bad_bytes",
                "unsupported_packets",
                "stream_periods",
                "frames_sent",
            ),
        )
        self.mode = Mode.OFF
        self._pending = bytearray()
        self._stream_ids: list[int] = []
        self._streaming = False
        self._threads.append(
            threading.Thread(target=self._stream_loop, name="create2-stream", daemon=True)
        )

    def receive(self, data: bytes) -> None:
        with self._lock:
            for byte in data:
                self._receive(byte)

    def _receive(self, byte: int) -> None:
        """One byte from the driver: complete the pending command and execute it."""
        if not self._pending and byte != oi.STREAM and byte not in _FIXED_DATA_LENGTHS:
            self.counters["bad_bytes"] += 1
            return
        self._pending.append(byte)
        needed = _data_length(self._pending)
        if needed is None or len(self._pending) < 1 + needed:
            return
        command = bytes(self._pending)
        self._pending.clear()
        self.opcodes[command[0]] += 1
        self._execute(command[0], command[1:])

    def _execute(self, opcode: int, data: bytes) -> None:
        if not self._accepts(opcode):
            self.counters["ignored_commands"] += 1
            return
        self.counters["commands"] += 1
        if opcode == oi.START:
            if self.mode in _DRIVING_MODES:
                self._backend.set_wheel_speeds(0.0, 0.0)
            self.mode = Mode.PASSIVE
        elif opcode == oi.SAFE:
            self.mode = Mode.SAFE
        elif opcode == oi.FULL:
            self.mode = Mode.FULL
        elif opcode == oi.DRIVE_DIRECT:
            self._drive_direct(data)
        elif opcode == oi.STREAM:
            self._request_stream(data[1:])
        elif opcode == oi.PAUSE_RESUME_STREAM:
            self._streaming = data[0] != 0 and bool(self._stream_ids)
        elif opcode == oi.SENSORS:
            self._answer_sensor(data[0])

    def _answer_sensor(self, packet_id: int) -> None:
        values = {
            oi.OI_MODE: list(Mode).index(self.mode),
            oi.BATTERY_CHARGE: self.battery_mah[0],
            oi.BATTERY_CAPACITY: self.battery_mah[1],
        }
        if packet_id not in values:
            self.counters["unsupported_packets"] += 1
            return
        self.send(oi.packet_data(packet_id, values[packet_id]))

    def _accepts(self, opcode: int) -> bool:
        """Off accepts only Start; Drive Direct needs Safe or Full."""
        if self.mode is Mode.OFF:
            return opcode == oi.START
        return opcode != oi.DRIVE_DIRECT or self.mode in _DRIVING_MODES

    def _drive_direct(self, data: bytes) -> None:
        right, left = (oi.clamp_wheel_speed(v) for v in oi.parse_drive_direct(data))
        self._backend.set_wheel_speeds(left / 1000.0, right / 1000.0)

    def _request_stream(self, packet_ids: bytes) -> None:
        supported = [i for i in packet_ids if i in _ENCODERS]
        self.counters["unsupported_packets"] += len(packet_ids) - len(supported)
        self._stream_ids = supported
        self._streaming = bool(supported)

    def _stream_loop(self) -> None:
        """A frame every STREAM_PERIOD_S on an absolute schedule; after a stall (more than one
        period late) the schedule restarts from now instead of sending a burst."""
        deadline = time.monotonic()
        while not self._stopping.wait(max(0.0, deadline - time.monotonic())):
            deadline += oi.STREAM_PERIOD_S
            if time.monotonic() > deadline:
                deadline = time.monotonic() + oi.STREAM_PERIOD_S
            with self._lock:
                self.counters["stream_periods"] += 1
                frame = self._frame() if self._streaming else None
            if frame is not None:
                self.send(frame, "frames_sent")

    def _frame(self) -> bytes:
        counts = dict(zip(_ENCODERS, self._backend.encoder_counts(), strict=True))
        return oi.stream_frame({i: oi.packet_data(i, counts[i]) for i in self._stream_ids})
