"""The emulated Create 2 (sim2d/devices/create2.py) driven through a real pty by pyserial."""

from __future__ import annotations

import random
import statistics
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import serial

from protocols import create_oi as oi
from sim2d.devices.create2 import Create2Emulator, Mode
from tests.sim2d.devices.conftest import SAFETY_S

WHEEL_DIAMETER_M = 0.072
START_COUNTS = 65_400
"""Both encoders start near 2^16, so the streamed counts wrap during a test."""


class RollingWheels:
    """The world for the emulator: wheels that take the commanded speed at once and count
    encoder ticks as they roll; ``sampled`` keeps when each count was taken (the emulator
    takes one a frame) and what it was."""

    def __init__(self) -> None:
        self.speeds = (0.0, 0.0)
        self.sampled: list[tuple[float, tuple[int, int]]] = []
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
            counts = (
                START_COUNTS + round(left / metres_per_count),
                START_COUNTS + round(right / metres_per_count),
            )
            self.sampled.append((time.monotonic(), counts))
        return counts

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


def frames(port: serial.Serial, count: int) -> list[dict[int, int]]:
    """The next ``count`` frames."""
    parser = oi.StreamParser()
    found: list[dict[int, int]] = []
    deadline = time.monotonic() + SAFETY_S
    while len(found) < count:
        assert time.monotonic() < deadline, f"{len(found)} of {count} frames in {SAFETY_S} s"
        found += [frame.packets for frame in parser.feed(port.read(max(1, port.in_waiting)))]
    return found[:count]


def wait_until(condition: Callable[[], bool], what: str) -> None:
    deadline = time.monotonic() + SAFETY_S
    while not condition():
        assert time.monotonic() < deadline, f"no {what} in {SAFETY_S} s"
        time.sleep(0.005)


def test_stream_period_and_counts_follow_drive_direct(
    robot: serial.Serial, wheels: RollingWheels
) -> None:
    """Each frame carries the counts the world had when the emulator built it, wrapped; the
    frames follow the 15 ms schedule, as the world's clock saw them built: never faster (a late
    frame does not bring a burst after it), and at most a few periods apart at the median (a
    wrong period; a busy machine makes them late, 22 ms apart at the median at load 15)."""
    robot.write(bytes([oi.START, oi.SAFE]) + oi.drive_direct(200, -100))
    robot.write(oi.stream_request([oi.LEFT_ENCODER, oi.RIGHT_ENCODER]))
    streamed = frames(robot, 31)
    assert wheels.speeds == (-0.1, 0.2)
    sampled = wheels.sampled[: len(streamed)]
    assert streamed == [
        {oi.LEFT_ENCODER: left % 2**16, oi.RIGHT_ENCODER: right % 2**16}
        for _, (left, right) in sampled
    ]
    assert any(frame[oi.RIGHT_ENCODER] < START_COUNTS for frame in streamed)
    built = [at for at, _ in sampled]
    assert built[-1] - built[0] >= (len(built) - 2) * oi.STREAM_PERIOD_S
    periods = [b - a for a, b in zip(built, built[1:], strict=False)]
    assert statistics.median(periods) < 4 * oi.STREAM_PERIOD_S


def test_drive_direct_before_safe_is_ignored(
    robot: serial.Serial, emulator: Create2Emulator, wheels: RollingWheels
) -> None:
    robot.write(oi.drive_direct(100, 100) + bytes([oi.START]) + oi.drive_direct(100, 100))
    robot.write(oi.stream_request([oi.LEFT_ENCODER]))
    frames(robot, 1)
    assert emulator.mode is Mode.PASSIVE
    assert wheels.speeds == (0.0, 0.0)
    assert emulator.counters["ignored_commands"] == 2


def test_pause_and_resume_stream(robot: serial.Serial, emulator: Create2Emulator) -> None:
    """Paused, the stream sends nothing for three of its periods, counted by the emulator's
    own clock (a frame built before the pause is out by the second period after it)."""
    robot.write(bytes([oi.START]) + oi.stream_request([oi.LEFT_ENCODER, 200]))
    assert list(frames(robot, 1)[0]) == [oi.LEFT_ENCODER]
    commands = emulator.counters["commands"]
    robot.write(oi.pause_resume(False))
    wait_until(lambda: emulator.counters["commands"] > commands, "pause handled")
    periods = emulator.counters["stream_periods"]
    wait_until(lambda: emulator.counters["stream_periods"] >= periods + 2, "two periods")
    robot.reset_input_buffer()
    sent, periods = emulator.counters["frames_sent"], emulator.counters["stream_periods"]
    wait_until(lambda: emulator.counters["stream_periods"] >= periods + 3, "three periods")
    assert robot.in_waiting == 0 and emulator.counters["frames_sent"] == sent
    robot.write(oi.pause_resume(True))
    frames(robot, 2)


def test_garbage_does_not_kill_the_emulator(
    robot: serial.Serial, emulator: Create2Emulator, wheels: RollingWheels
) -> None:
    noise = random.Random(7).randbytes(4000)
    # At most 1 + 1 + 255 bytes finish whatever command the noise began; the rest are Starts.
    robot.write(noise + bytes([oi.START]) * 300)
    robot.write(bytes([oi.FULL]) + oi.drive_direct(-50, 50) + oi.stream_request([44, 43]))
    asked = [oi.RIGHT_ENCODER, oi.LEFT_ENCODER]
    parser = oi.StreamParser()
    deadline = time.monotonic() + SAFETY_S
    while not any(list(frame.packets) == asked for frame in parser.feed(robot.read(1))):
        assert time.monotonic() < deadline, f"no frame of {asked} in {SAFETY_S} s"
    assert [list(frame) for frame in frames(robot, 2)] == [asked, asked]
    assert emulator.mode is Mode.FULL
    assert wheels.speeds == (0.05, -0.05)
    assert emulator.counters["bad_bytes"] > 0


def test_link_lives_while_running_and_stop_ends_every_thread(
    wheels: RollingWheels, tmp_path: Path
) -> None:
    """Stopped while it streams and a driver still holds the port open, the emulator ends its
    threads (each waits at most READ_TIMEOUT_S between looks at the stop) and removes its link."""
    link = tmp_path / "ttyCreate"
    link.write_text("a stale file in the way")
    emulator = Create2Emulator(wheels, link=link)
    emulator.start()
    assert link.resolve() == Path(emulator.port).resolve()
    with serial.Serial(str(link), oi.BAUD, timeout=0.5) as port:
        port.write(bytes([oi.START]) + oi.stream_request([oi.LEFT_ENCODER]))
        frames(port, 1)
        emulator.stop()
    assert not any(thread.is_alive() for thread in emulator._threads)
    assert not link.exists() and not link.is_symlink()
    emulator.stop()
