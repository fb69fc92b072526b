"""A message stamped far outside its session (a goal stamped on the wall clock in a simulated
session, as `topic pub` once did) is said in one line naming its topic by the recorder, `info`,
`replay`, `report` and the judge, and left out: `info` gives the session's true span, a replay
ends, a report is written whole."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from analysis.judge import JUDGED, judge
from launch.query import live_components, statuses
from messages import codec, topics
from messages.clock import Clock
from messages.goal import Goal
from messages.header import Header
from messages.topics import CONTROL_GOAL, GOAL_REQUEST
from profiles.endpoints import free_port
from profiles.profile import load_profile
from record.session_reader import info
from record.session_span import FAR_NS, Span
from record.sessions import load_session
from studies.launched import connect, launched
from tests.analysis.conftest import DT, FIGURES, ROBOT, START_NS, session_of, write
from tests.parsimony.in_process import run_in_process
from tests.processes import parsimony
from wbc.geometry import scenarios
from wbc.laws.kinematic_run import integrate
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.task import PoseTask

NAMESPACE = "far"


def header(stamp_ns: int, source: str) -> Header:
    return Header(stamp_ns=stamp_ns, frame="world", seq=0, source=source)


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(clean, poisoned): a simulated LP run of some 10 s under a staging supervisor (its
    goals a drive leg to a point, a turn, then the pose), and the same with the operator's
    goal on goal/request stamped on the wall clock, as `topic pub` stamped it."""
    task = PoseTask(ROBOT.fkm(scenarios.REACH_GOAL))
    session = session_of(
        integrate(LPLaw(ROBOT, LPParams()), scenarios.HOME, task, DT, 1500), "lp", task
    )
    arm, start_ns = tuple(scenarios.HOME[3:].tolist()), START_NS
    session[CONTROL_GOAL.name] = [
        Goal(
            header=header(start_ns, "supervisor"),
            task="point",
            point=(0.5, 0.0),
            arm=arm,
            lookahead=0.1,
        ),
        Goal(
            header=header(start_ns + 10**9, "supervisor"),
            task="heading",
            heading=0.0,
            arm=arm,
            point=(0.5, 0.0),
        ),
        Goal(header=header(start_ns + 2 * 10**9, "supervisor"), task="pose", pose=tuple(task.pose)),
    ]
    folder = tmp_path_factory.mktemp("far")
    goal = Goal(header=header(time.time_ns(), "topic"), task="pose", pose=tuple(task.pose))
    return write(folder / "clean.mcap", session), write(folder / "poisoned.mcap", session, goal)


def said(stderr: str, what: str) -> list[str]:
    return [line for line in stderr.splitlines() if what in line]


def test_info_gives_the_true_span_and_names_the_far_stamp_in_one_line(
    files, capsys: pytest.CaptureFixture[str]
) -> None:
    clean, poisoned = (run_in_process(["info", str(f), "--json"], capsys) for f in files)
    assert clean[0] == poisoned[0] == 0, poisoned[2]
    found, expected = json.loads(poisoned[1]), json.loads(clean[1])
    for field in ("start_ns", "end_ns", "duration_s", "messages"):
        assert found[field] == expected[field], field
    assert 10 < found["duration_s"] < 20
    assert list(found["outside"]) == [GOAL_REQUEST.key(NAMESPACE)]
    lines = said(poisoned[2], "far outside the session")
    assert len(lines) == 1 and "1 message of far/goal/request" in lines[0], poisoned[2]
    assert found["warning"] in lines[0]
    assert clean[2] == "" and expected["warning"] is None


def test_a_replay_of_it_ends_and_says_what_it_did_not_send(
    files, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    profile = tmp_path / "far.yaml"
    profile.write_text(
        yaml.safe_dump(
            {
                "namespace": NAMESPACE,
                "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
                "components": [{"name": "pub", "module": "scripted_publisher", "role": "tool"}],
            }
        )
    )  # never launched: the replay has no router to reach, and serves its own
    clean = json.loads(run_in_process(["info", str(files[0]), "--json"], capsys)[1])
    done = parsimony("replay", str(files[1]), "--profile", str(profile), "--rate", "20")
    assert done.returncode == 0, done.stderr
    assert f"/ {clean['duration_s']:.2f} s" in done.stderr
    assert f"{clean['messages']} messages sent" in done.stderr
    lines = said(done.stderr, "far outside the session")
    assert len(lines) == 1 and "not sent" in lines[0] and "goal/request" in lines[0]


def test_a_report_of_it_is_written_whole_and_says_what_it_left_out(
    files, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "report"
    code, printed, err = run_in_process(
        ["report", str(files[1]), "--out", str(out), "--json"], capsys
    )
    assert code == 0, err
    assert "Traceback" not in err
    assert {Path(f).name for f in json.loads(printed)["figures"]} == set(FIGURES)
    lines = said(err, "far outside the session")
    assert len(lines) == 1 and "far/goal/request" not in lines[0] and "goal/request" in lines[0]
    # The judge says so too, and judges the rest as it judges the clean recording.
    judged = json.loads((out / "judged.json").read_text())["lp"]
    assert "1 message of goal/request" in judged.pop("outside_session")
    expected = judge(load_session(files[0], JUDGED), ROBOT)
    assert expected.pop("outside_session") is None
    assert judged == json.loads(json.dumps(expected))


def test_the_session_is_the_stretch_without_a_days_gap_that_holds_the_most() -> None:
    span = Span()
    for stamp in (5, *range(FAR_NS * 3, FAR_NS * 3 + 100), 10 * FAR_NS):
        span.add(stamp)
    assert span.session() == (FAR_NS * 3, FAR_NS * 3 + 99)
    span.add(FAR_NS * 3 + 99 + FAR_NS)  # a day later: the same session, one day longer
    assert span.session() == (FAR_NS * 3, FAR_NS * 4 + 99)


def test_the_recorder_says_once_which_topic_was_stamped_far_outside_the_session(
    tmp_path: Path,
) -> None:
    """On simulated time, a goal stamped on the wall clock (as `topic pub` stamped it) is
    recorded and said in one line naming its topic; `info` leaves it out of the span."""
    profile = tmp_path / "sim.yaml"
    profile.write_text(
        yaml.safe_dump(
            {
                "namespace": "rec",
                "clock": "sim",
                "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
                "components": [
                    {
                        "name": "pub",
                        "module": "scripted_publisher",
                        "role": "tool",
                        "params": {"rate_hz": 50.0},
                    }
                ],
            }
        )
    )
    out = tmp_path / "far.mcap"
    with launched(profile) as launcher, connect(load_profile(profile), launcher) as session:
        command = subprocess.Popen(
            [sys.executable, "-m", "parsimony.cli", "record", str(profile), "-o", str(out)],
            stderr=subprocess.PIPE,
            text=True,
        )
        while "recorder" not in live_components(session, "rec", 0.5):
            assert command.poll() is None and launcher.poll() is None, "record or launch ended"
        clock = session.declare_publisher(topics.SIM_CLOCK.key("rec"))
        goals = session.declare_publisher(topics.GOAL_REQUEST.key("rec"))
        for tick in range(1, 101):  # a simulated second
            clock.put(codec.encode(Clock(stamp_ns=tick * 10_000_000)))
            if tick in (50, 60):
                goal = Goal(
                    header=Header(stamp_ns=time.time_ns(), frame="world", seq=tick, source="topic"),
                    task="position",
                    position=(1.0, 0.0, 0.5),
                )
                goals.put(codec.encode(goal))
        deadline = time.monotonic() + 60.0  # a safety net: the recorder counts them in 0.1 s
        while statuses(session, "rec")["recorder"].counters.get("outside.goal/request") != 2:
            assert command.poll() is None and time.monotonic() < deadline, "never counted"
            time.sleep(0.1)  # the recorder's queue is written in its own time
        command.send_signal(signal.SIGINT)
        _, stderr = command.communicate()
    assert command.returncode == 0, stderr
    lines = [line for line in stderr.splitlines() if "far outside the session" in line]
    assert len(lines) == 1 and "1 message of goal/request" in lines[0], stderr
    found = info(out)
    assert list(found["outside"]) == ["rec/goal/request"]
    assert found["outside"]["rec/goal/request"]["messages"] == 2
    assert found["end_ns"] <= 100 * 10_000_000
