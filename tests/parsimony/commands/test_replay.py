"""`parsimony replay` with no system running: it serves a router of its own on the profile's
loopback endpoint, and the replay is watched in Foxglove as a live system is, through
`replay --view` and through `parsimony view` of the same profile; under ``--lockstep`` it says
each message nothing answered within ``--answer-timeout``, and goes on."""

from __future__ import annotations

import asyncio
import signal
from pathlib import Path

import pytest

from messages import topics
from messages.state import RobotState
from parsimony.target_options import PROFILE_ENV
from profiles.endpoints import free_port
from record.replayer import Recording
from record.session_file import SessionWriter, from_json
from tests.parsimony.in_process import completed
from tests.record.session_messages import image
from tests.view.live_view_client import (
    StderrLines,
    background_job,
    state,
    stopped_by,
    watch,
    write_profile,
)

RECORDED = "rec"
INTO = "other"
STATES = 50


def recording(path: Path) -> dict[int, RobotState]:
    """A second of robot states at 50 Hz, recorded in ``RECORDED``; by stamp."""
    states = {s.header.stamp_ns: s for s in map(state, range(STATES))}
    with SessionWriter(path) as writer:
        for message in states.values():
            writer.write(topics.ROBOT_STATE.key(RECORDED), message)
    return states


def watched(address: str, channel: str) -> tuple[int, bytes]:
    """The first (log time, payload) a Foxglove client subscribed to ``channel`` reads."""
    return asyncio.run(watch(address, {channel}))[1][channel]


def test_a_replay_with_no_system_serves_its_own_router_and_is_watched_live(tmp_path: Path) -> None:
    """Both started as a shell's background job (SIGINT ignored), they stop on SIGINT and
    SIGTERM, and say what they did."""
    profile = write_profile(tmp_path)  # its router's port is free: nothing is running
    states = recording(tmp_path / "k.mcap")
    port = free_port()
    replay = background_job(
        "replay",
        str(tmp_path / "k.mcap"),
        "--profile",
        str(profile),
        "--loop",
        "--namespace",
        INTO,
        "--view",
        "--port",
        str(port),
    )
    said = StderrLines(replay)
    view = None
    try:
        assert "the replay serves its own there" in said.wait_for("no router at")
        address = f"ws://127.0.0.1:{port}"
        assert f"view: {INTO} live at {address}" in said.wait_for(" live at ")
        channel = topics.ROBOT_STATE.key(INTO)
        log_time, payload = watched(address, channel)
        assert from_json(payload, RobotState) == states[log_time]
        # `parsimony view` of the profile reaches the replay's router, and watches it too.
        view = background_job("view", str(profile), "--namespace", INTO, "--port", "0")
        view_said = StderrLines(view)
        line = view_said.wait_for(" live at ")
        log_time, payload = watched(line.split(" live at ")[1].split()[0], channel)
        assert from_json(payload, RobotState) == states[log_time]
        assert stopped_by(view, signal.SIGINT) == 0
        assert " messages shown, " in view_said.all(), view_said.all()
        assert stopped_by(replay, signal.SIGTERM) == 143
    finally:
        for process in (view, replay):
            if process is not None and process.poll() is None:
                process.kill()
    assert "Traceback" not in said.all(), said.all()
    assert " messages sent (interrupted)\n" in said.all()
    assert " messages shown, " in said.all()  # what its view did
    assert said.all().endswith("[replay] interrupted by SIGTERM\n")


def test_without_a_profile_a_replay_goes_into_its_recorded_namespace(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    recording(tmp_path / "one.mcap")
    assert Recording.of(tmp_path / "one.mcap", lambda _: True).namespace() == RECORDED
    with SessionWriter(tmp_path / "two.mcap") as writer:
        for namespace in (RECORDED, INTO):
            writer.write(topics.ROBOT_STATE.key(namespace), state(0))
    monkeypatch.delenv(PROFILE_ENV, raising=False)
    done = completed("replay", str(tmp_path / "two.mcap"))
    assert done.returncode == 2, done.stderr
    assert done.stderr == (
        f"replay: {tmp_path / 'two.mcap'}: recorded in the namespaces "
        f"{INTO}, {RECORDED}: give --namespace\n"
    )


def test_a_lockstep_replay_that_nothing_answers_says_so_after_the_timeout_given(
    tmp_path: Path,
) -> None:
    profile = write_profile(tmp_path)  # nothing is running: no tracker, no estimator
    frames = [10**9 + k * 10**8 for k in range(3)]
    with SessionWriter(tmp_path / "frames.mcap") as writer:
        for stamp in frames:
            writer.write(topics.CAMERA_IMAGE.key(RECORDED), image(stamp))
    done = completed(
        "replay",
        str(tmp_path / "frames.mcap"),
        "--profile",
        str(profile),
        "--namespace",
        INTO,
        "--lockstep",
        "--answer-timeout",
        "0.05",
        "--rate",
        "100",
    )
    assert done.returncode == 0, done.stderr
    for stamp in frames:
        assert f"no answer to camera/image of {stamp / 1e9:.3f} s in 0.05 s; going on" in (
            done.stderr
        ), done.stderr
    assert "3 messages not answered within 0.05 s" in done.stderr, done.stderr
