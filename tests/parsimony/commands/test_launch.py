"""`parsimony launch PROFILE`: a --duration that is not a positive number of seconds refused, and
`--record FILE`: the profile and a recorder of every topic, as a
newcomer's first hour runs it (before, a recording needed a second command in a second
terminal, `parsimony record`, started after the launch, which missed the session's start)."""

from __future__ import annotations

import json
import signal
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from launch import query
from profiles.deploy_files import ROBOT_FILE
from tests.parsimony.in_process import run_in_process

if TYPE_CHECKING:
    from tests.launch.conftest import LaunchFixture, ProfileWriter

PUB = {"name": "pub", "module": "scripted_publisher", "role": "tool", "params": {"rate_hz": 50.0}}
CTL = {"name": "ctl", "module": "lp_controller", "role": "controller"}


def test_the_recording_holds_the_sessions_topics_and_is_whole_after_sigint(
    write_profile: ProfileWriter,
    launch: LaunchFixture,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The recorder starts first, the others once it is alive, and it stops last; --force
    replaces an older file."""
    profile = write_profile([PUB, CTL], robot=str(ROBOT_FILE))
    recording = tmp_path / "first.mcap"
    recording.write_text("an older file")
    launched = launch(profile, "--record", str(recording), "--force")
    launched.wait_for(r"\[launch\] all 3 components alive")
    with query.Target.from_profile(profile).open() as session:
        deadline = time.monotonic() + 30.0  # a safety net: the controller answers in 0.1 s
        while not query.status_of(session, "test", "recorder").counters.get(
            "received.base/command"
        ):  # until the controller's commands reach the recorder
            assert time.monotonic() < deadline, launched.text()

    assert launched.stop(signal.SIGINT) == 0
    text = launched.text()
    alive, started = text.index("[launch] recorder alive"), text.index("[launch] started pub ")
    assert alive < started, "the others start once the recorder is alive"
    assert text.index("[launch] ctl stopped (0)") < text.index("[launch] recorder stopped (0)")
    code, out, err = run_in_process(["info", str(recording), "--json"], capsys)
    assert code == 0, err
    found = json.loads(out)
    assert found["complete"], "the recorder wrote its footer"
    topics = {channel["topic"] for channel in found["channels"]}
    assert {"robot/state", "control/goal", "base/command", "arm/command"} <= topics


def test_an_existing_file_is_refused_before_anything_starts(
    write_profile: ProfileWriter, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    profile = write_profile([PUB])
    recording = tmp_path / "first.mcap"
    recording.write_text("yesterday's session")
    code, _, err = run_in_process(["launch", str(profile), "--record", str(recording)], capsys)
    assert code == 2
    assert err.splitlines() == [f"launch: {recording} exists; give --force to replace it"]
    assert recording.read_text() == "yesterday's session"


def test_a_profile_that_already_records_is_refused(
    write_profile: ProfileWriter, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One recording, to the file the user named: not a second one beside the profile's."""
    recorder = {
        "name": "rec",
        "module": "recorder",
        "role": "recorder",
        "params": {"path": str(tmp_path / "its.mcap")},
    }
    profile = write_profile([PUB, recorder])
    argv = ["launch", str(profile), "--record", str(tmp_path / "mine.mcap")]
    code, _, err = run_in_process(argv, capsys)
    assert code == 2
    (line,) = err.splitlines()
    assert "already records" in line and "'rec'" in line and "without --record" in line
    assert not (tmp_path / "mine.mcap").exists() and not (tmp_path / "its.mcap").exists()


@pytest.mark.parametrize("duration", ["nan", "inf", "-1", "0", "soon"])
def test_launch_refuses_a_duration_that_is_not_a_positive_number_of_seconds(duration, capsys):
    code, _, err = run_in_process(
        ["launch", "deploy/controllers.yaml", "--duration", duration], capsys
    )
    assert code == 2
    assert "--duration" in err and repr(duration) in err
