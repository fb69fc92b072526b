"""`parsimony replay` driven from a terminal: a real process whose stdin is a pseudo-terminal,
publishing a real MCAP recording into a real Zenoh router on loopback; and the schedule
the keys re-anchor."""

from __future__ import annotations

import os
import pty
import queue
import subprocess
import sys
import termios
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml
import zenoh

from messages import codec, topics
from messages.header import Header
from messages.odometry import BaseOdometry
from profiles.endpoints import free_port
from profiles.profile import load_profile
from record.replayer import Pace
from record.session_file import SessionWriter

MESSAGES = 30
STEP_NS = 10_000_000
DEADLINE_S = 20.0
QUIET_S = 0.3
"""How long "nothing more arrives" is watched, once something showed it would have."""


def odometry(index: int) -> BaseOdometry:
    header = Header(
        stamp_ns=1_000_000_000 + index * STEP_NS, frame="odom", seq=index, source="base_driver"
    )
    return BaseOdometry(
        header=header,
        left_encoder=index,
        right_encoder=2 * index,
        left_distance=index * 1e-3,
        right_distance=index * 2e-3,
        x=index * 1e-3,
        y=0.0,
        phi=index * 1e-4,
        forward_velocity=0.1,
        angular_velocity=0.01,
    )


@pytest.fixture
def recording(tmp_path: Path) -> list[BaseOdometry]:
    messages = [odometry(i) for i in range(MESSAGES)]
    with SessionWriter(tmp_path / "session.mcap") as writer:
        for message in messages:
            writer.write(topics.BASE_ODOMETRY.key("recorded"), message)
    return messages


@dataclass
class Replay:
    """A running `parsimony replay --start-paused` on a pseudo-terminal, what it printed on
    stderr (line by line) and the odometry its router received."""

    process: subprocess.Popen
    terminal: int
    """The master side: what is written here is typed on the replay's stdin."""
    replica: int
    """The replay's stdin, kept open to read its terminal settings."""
    lines: queue.Queue
    received: queue.Queue

    def press(self, key: bytes) -> None:
        os.write(self.terminal, key)

    def wait_for_line(self, *words: str) -> str:
        deadline = time.monotonic() + DEADLINE_S
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=deadline - time.monotonic())
            except queue.Empty:
                break
            if all(word in line for word in words):
                return line
        raise AssertionError(f"no stderr line with {words} in {DEADLINE_S} s")

    def next_message(self) -> BaseOdometry:
        return self.received.get(timeout=DEADLINE_S)

    def assert_quiet(self) -> None:
        """Nothing more arrives for ``QUIET_S``."""
        with pytest.raises(queue.Empty):
            extra = self.received.get(timeout=QUIET_S)
            raise AssertionError(f"unexpected message {extra.header}")


@pytest.fixture
def replay(tmp_path: Path, recording) -> Iterator[Replay]:
    profile = tmp_path / "replay.yaml"
    component = {"name": "x", "module": "scripted_publisher", "role": "tool"}
    router = {"router": [f"tcp/127.0.0.1:{free_port()}"]}
    profile.write_text(
        yaml.safe_dump({"namespace": "replayed", "components": [component], "zenoh": router})
    )
    received: queue.Queue = queue.Queue()
    with zenoh.open(load_profile(profile).zenoh.router_config()) as router:
        router.declare_subscriber(
            topics.BASE_ODOMETRY.key("replayed"),
            lambda s: received.put(codec.decode(s.payload.to_bytes(), BaseOdometry)),
        )
        terminal, replica = pty.openpty()
        command = [
            sys.executable,
            "-m",
            "parsimony.cli",
            "replay",
            str(tmp_path / "session.mcap"),
            "--profile",
            str(profile),
            "--start-paused",
        ]
        process = subprocess.Popen(
            command, stdin=replica, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
        )
        lines: queue.Queue = queue.Queue()
        threading.Thread(
            target=lambda: [lines.put(line) for line in process.stderr], daemon=True
        ).start()
        try:
            yield Replay(process, terminal, replica, lines, received)
        finally:
            if process.poll() is None:
                process.kill()
            process.wait(DEADLINE_S)
            os.close(terminal)
            os.close(replica)


def test_paused_replay_steps_three_messages_then_plays_the_rest(replay: Replay, recording) -> None:
    before = termios.tcgetattr(replay.replica)
    replay.wait_for_line("paused", f"0.00 / {(MESSAGES - 1) * STEP_NS / 1e9:.2f} s")
    # The replay reads single keys: the terminal is in cbreak mode (no line editing).
    assert not termios.tcgetattr(replay.replica)[3] & termios.ICANON
    replay.assert_quiet()
    for index in range(3):
        replay.press(b"s" if index != 1 else b"\x1b[C")  # the right arrow steps as well
        assert replay.next_message().header == recording[index].header
    replay.assert_quiet()
    replay.press(b" ")
    rest = [replay.next_message() for _ in range(MESSAGES - 3)]
    assert [m.header for m in rest] == [m.header for m in recording[3:]]
    assert rest[-1] == recording[-1]
    assert replay.process.wait(DEADLINE_S) == 0
    assert termios.tcgetattr(replay.replica) == before
    replay.assert_quiet()


def test_q_quits_with_status_0_and_gives_the_terminal_back(replay: Replay) -> None:
    before = termios.tcgetattr(replay.replica)
    replay.wait_for_line("paused", "rate 1 ")
    replay.press(b"+")
    replay.wait_for_line("paused", "rate 2 ")
    replay.press(b"q")
    assert replay.process.wait(DEADLINE_S) == 0
    assert termios.tcgetattr(replay.replica) == before
    replay.wait_for_line("0 messages sent (quit)")
    replay.assert_quiet()


def test_the_schedule_is_re_anchored_where_the_recorded_time_stands() -> None:
    """Pausing, resuming and changing the rate keep what was left of a gap, scaled."""
    pace = Pace(rate=1.0, anchor_ns=0, anchor_s=100.0)
    assert pace.due_s(700_000_000) == pytest.approx(100.7)
    pace.toggle(100.5, 700_000_000)  # paused half a second in
    assert pace.paused and pace.now_ns(150.0, 700_000_000) == 500_000_000
    pace.toggle(200.0, 700_000_000)  # resumed 99.5 s later: 0.2 s of the gap are left
    assert pace.due_s(700_000_000) == pytest.approx(200.2)
    pace.scale(2.0, 200.1, 700_000_000)  # 0.1 s of recorded time left, now twice as fast
    assert pace.rate == 2.0 and pace.due_s(700_000_000) == pytest.approx(200.15)
    for _ in range(10):
        pace.scale(2.0, 200.1, 700_000_000)
    assert pace.rate == 64.0
    for _ in range(20):
        pace.scale(0.5, 200.1, 700_000_000)
    assert pace.rate == 1 / 64
