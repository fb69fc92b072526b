"""The emulated Create 2 (sim2d/devices/create2.py) driven through a real pty by pyserial."""

from __future__ import annotations

import random
import statistics
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import serial

from protocols import create_oi as oi
from sim2d.devices.create2 import Create2Emulator, Mode

WHEEL_DIAMETER_M = 0.072
START_COUNTS = 65_400
"""Both encoders start near 2^16, so the streamed counts wrap during a test."""


class RollingWheels:
    """The world for the emulator: wheels that take the commanded speed at once and count
    encoder ticks as they roll."""

    def __init__(self) -> None:
        self.speeds = (0.0, 0.0)
        self._distance_m = (0.0, 0.0)
        self._since = time.monotonic()
        self._lock = threading.Lock()

    def set_wheel_speeds(self, left: float, right: float) -> None:
        with self._lock:
            self._distance_m = self._rolled()
            self._since = time.monotonic()
            self.speeds = (left, right)

    def encoder_counts(self) -> tuple[int, int]:
        metres_per_count = oi.mm_per_count(WHEEL_DIAMETER_M) / 1000.0
        with self._lock:
            left, right = self._rolled()
        return (
            START_COUNTS + round(left / metres_per_count),
            START_COUNTS + round(right / metres_per_count),
        )

    def _rolled(self) -> tuple[float, float]:
        dt = time.monotonic() - self._since
        return (
            self._distance_m[0] + self.speeds[0] * dt,
            self._distance_m[1] + self.speeds[1] * dt,
        )


@pytest.fixture
def wheels() -> RollingWheels:
    return RollingWheels()


@pytest.fixture
def emulator(wheels: RollingWheels, tmp_path: Path) -> Iterator[Create2Emulator]:
    with Create2Emulator(wheels, link=tmp_path / "create2") as emulator:
        yield emulator


@pytest.fixture
def robot(emulator: Create2Emulator) -> Iterator[serial.Serial]:
    with serial.Serial(emulator.port, oi.BAUD, timeout=0.5) as port:
        yield port


def timed_frames(
    port: serial.Serial, count: int, timeout_s: float = 2.0
) -> list[tuple[float, dict[int, int]]]:
    """The next ``count`` frames with the time each was read."""
    parser = oi.StreamParser()
    frames: list[tuple[float, dict[int, int]]] = []
    deadline = time.monotonic() + timeout_s
    while len(frames) < count and time.monotonic() < deadline:
        data = port.read(max(1, port.in_waiting))
        now = time.monotonic()
        frames += [(now, frame.packets) for frame in parser.feed(data)]
    assert len(frames) >= count, f"{len(frames)} of {count} frames in {timeout_s} s"
    return frames[:count]


def test_stream_period_and_counts_follow_drive_direct(
    robot: serial.Serial, wheels: RollingWheels
) -> None:
    right_mm_s, left_mm_s = 200, -100
    robot.write(bytes([oi.START, oi.SAFE]) + oi.drive_direct(right_mm_s, left_mm_s))
    robot.write(oi.stream_request([oi.LEFT_ENCODER, oi.RIGHT_ENCODER]))
    frames = timed_frames(robot, 31)

    periods_ms = [1000 * (b[0] - a[0]) for a, b in zip(frames, frames[1:], strict=False)]
    assert statistics.median(periods_ms) == pytest.approx(15.0, abs=3.0)
    assert wheels.speeds == (-0.1, 0.2)

    (t0, first), (t1, last) = frames[1], frames[-1]
    counts_per_s = [
        oi.encoder_delta(last[i], first[i]) / (t1 - t0) for i in (oi.LEFT_ENCODER, oi.RIGHT_ENCODER)
    ]
    per_count_mm = oi.mm_per_count(WHEEL_DIAMETER_M)
    assert counts_per_s[0] == pytest.approx(left_mm_s / per_count_mm, rel=0.15)
    assert counts_per_s[1] == pytest.approx(right_mm_s / per_count_mm, rel=0.15)
    assert any(frame[oi.RIGHT_ENCODER] < START_COUNTS for _, frame in frames)


def test_drive_direct_before_safe_is_ignored(
    robot: serial.Serial, emulator: Create2Emulator, wheels: RollingWheels
) -> None:
    robot.write(oi.drive_direct(100, 100) + bytes([oi.START]) + oi.drive_direct(100, 100))
    robot.write(oi.stream_request([oi.LEFT_ENCODER]))
    timed_frames(robot, 1)
    assert emulator.mode is Mode.PASSIVE
    assert wheels.speeds == (0.0, 0.0)
    assert emulator.counters["ignored_commands"] == 2


def test_pause_and_resume_stream(robot: serial.Serial) -> None:
    robot.write(bytes([oi.START]) + oi.stream_request([oi.LEFT_ENCODER, 200]))
    assert list(timed_frames(robot, 1)[0][1]) == [oi.LEFT_ENCODER]
    robot.write(oi.pause_resume(False))
    time.sleep(0.05)
    robot.reset_input_buffer()
    time.sleep(0.05)
    assert robot.in_waiting == 0
    robot.write(oi.pause_resume(True))
    timed_frames(robot, 2)


def test_garbage_does_not_kill_the_emulator(
    robot: serial.Serial, emulator: Create2Emulator, wheels: RollingWheels
) -> None:
    noise = random.Random(7).randbytes(4000)
    # At most 1 + 1 + 255 bytes finish whatever command the noise began; the rest are Starts.
    robot.write(noise + bytes([oi.START]) * 300)
    robot.write(bytes([oi.FULL]) + oi.drive_direct(-50, 50) + oi.stream_request([44, 43]))
    time.sleep(0.05)
    robot.reset_input_buffer()
    (_, frame), *_ = timed_frames(robot, 2)
    assert list(frame) == [oi.RIGHT_ENCODER, oi.LEFT_ENCODER]
    assert emulator.mode is Mode.FULL
    assert wheels.speeds == (0.05, -0.05)
    assert emulator.counters["bad_bytes"] > 0


def test_link_lives_while_running_and_stop_is_prompt(wheels: RollingWheels, tmp_path: Path) -> None:
    link = tmp_path / "ttyCreate"
    link.write_text("a stale file in the way")
    emulator = Create2Emulator(wheels, link=link)
    emulator.start()
    assert link.resolve() == Path(emulator.port).resolve()
    with serial.Serial(str(link), oi.BAUD, timeout=0.5) as port:
        port.write(bytes([oi.START]) + oi.stream_request([oi.LEFT_ENCODER]))
        timed_frames(port, 1)
    began = time.monotonic()
    emulator.stop()
    assert time.monotonic() - began < 0.2
    assert not link.exists() and not link.is_symlink()
    emulator.stop()
