"""`parsimony status` and `parsimony param` against a launched system on loopback (run by the
command's entry point in the test's process; stdout the result alone in a process of its own:
test_status_json_is_the_whole_stdout_of_the_command)."""

from __future__ import annotations

import argparse
import json
import math
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
import zenoh

from launch import query
from messages import codec
from messages.goal import Goal
from parsimony.commands import param, status
from parsimony.target_options import PROFILE_ENV
from tests.parsimony.in_process import completed as cli  # in this process: no Python start
from tests.view.live_view_client import StderrLines, background_job, stopped_by
from wbc import dq


def command(module: object, *argv: str) -> int:
    """Run one subcommand through its own parser, as `parsimony` would."""
    root = argparse.ArgumentParser(prog="parsimony")
    module.add_parser(root.add_subparsers())
    return module.run(root.parse_args(argv))


def wait_for_first_message(profile: Path) -> None:
    """Wait until `pub` reports a published state, so its counters are not all zero."""
    target = query.Target.from_profile(profile)
    deadline = time.monotonic() + 10.0
    with target.open() as session:
        while query.statuses(session, "test")["pub"].counters["published.robot/state"] == 0:
            assert time.monotonic() < deadline, "pub published nothing in 10 s"


def test_status_lists_live_components_with_counters(
    running_pub: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    wait_for_first_message(running_pub)
    assert command(status, "status", str(running_pub)) == 0
    table = capsys.readouterr().out.splitlines()
    assert table[0].split()[:4] == ["NAME", "MODULE", "STATE", "PID"]
    assert table[1].split()[:3] == ["pub", "scripted_publisher", "running"]
    assert int(table[1].split()[5]) >= 1  # messages published; each counter under --counters

    assert command(status, "status", "--profile", str(running_pub), "--json") == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["name"] == "pub" and row["status"]["module"] == "scripted_publisher"
    assert set(row["status"]["parameters"]) >= {"rate_hz", "goal_task"}
    assert row["status"]["counters"]["published.control/goal"] >= 1


def test_status_json_is_the_whole_stdout_of_the_command(running_pub: Path) -> None:
    """`parsimony status --json` as a user runs it: a process whose stdout is only JSON."""
    wait_for_first_message(running_pub)
    result = subprocess.run(
        [sys.executable, "-m", "parsimony.cli", "status", str(running_pub), "--json"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stderr
    (row,) = json.loads(result.stdout)
    assert row["name"] == "pub"


def test_status_of_an_empty_namespace_or_a_remote_router_fails(
    running_pub: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    router = status.target_of(argparse.Namespace(profile=running_pub, target=None)).zenoh.router[0]
    assert command(status, "status", "nobody", "--router", router, "--timeout", "0.5") == 1
    assert "no live component in namespace 'nobody'" in capsys.readouterr().err
    assert command(status, "status", "test", "--router", "tcp/10.1.2.3:7447") == 2
    assert "not on the loopback interface" in capsys.readouterr().err


def test_param_set_then_get_changes_the_running_component(
    running_pub: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    assert command(param, "param", "get", "pub", "rate_hz", "--profile", str(running_pub)) == 0
    assert capsys.readouterr().out.strip() == "pub.rate_hz = 50.0"
    assert (
        command(param, "param", "set", "pub", "rate_hz", "25", "--profile", str(running_pub)) == 0
    )
    assert capsys.readouterr().out.strip() == "pub.rate_hz = 25.0"
    monkeypatch.setenv(PROFILE_ENV, str(running_pub))
    assert command(param, "param", "get", "pub", "rate_hz") == 0
    assert capsys.readouterr().out.strip() == "pub.rate_hz = 25.0"
    assert command(param, "param", "set", "pub", "goal_task", "pose") == 0
    assert capsys.readouterr().out.strip() == 'pub.goal_task = "pose"'


@pytest.mark.parametrize(
    ("argv", "error"),
    [
        (("set", "pub", "rate_hz", "-1"), "rate_hz: expected a float in [0.1, 1000.0], got -1.0"),
        (
            ("set", "pub", "rate_hz", "fast"),
            "rate_hz: expected a float in [0.1, 1000.0], got 'fast'",
        ),
        (("set", "pub", "goal_task", "dance"), "goal_task: expected a str in {'position', 'pose'}"),
        (("get", "pub", "nope"), "pub has no parameter at test/component/pub/param/nope"),
        (("get", "ghost", "rate_hz", "--timeout", "0.5"), "no reply from 'ghost'"),
    ],
)
def test_param_errors_are_reported(
    running_pub: Path, capsys: pytest.CaptureFixture[str], argv: tuple[str, ...], error: str
) -> None:
    assert command(param, "param", *argv, "--profile", str(running_pub)) == 1
    assert error in capsys.readouterr().err


def test_topic_echo_prints_each_decoded_message_as_a_json_line(running_pub: Path) -> None:
    result = cli("topic", "echo", "robot/state", "--count", "3", "--profile", str(running_pub))
    assert result.returncode == 0, result.stderr
    lines = [json.loads(line) for line in result.stdout.splitlines()]
    assert len(lines) == 3 and {line["header"]["source"] for line in lines} == {"pub"}
    seqs = [line["header"]["seq"] for line in lines]
    assert seqs == sorted(seqs) and len(lines[0]["arm_joints"]) == 5


def test_topic_hz_measures_the_rate_of_a_live_topic(running_pub: Path) -> None:
    result = cli(
        "topic", "hz", "robot/state", "--window", "1.0", "--json", "--profile", str(running_pub)
    )
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["messages"] > 5 and report["rate_hz"] > 5.0
    assert report["period_min_s"] <= report["period_median_s"] <= report["period_max_s"]


def test_topic_list_info_and_pub(running_pub: Path) -> None:
    rows = json.loads(cli("topic", "list", "--json", "--profile", str(running_pub)).stdout)
    state = next(row for row in rows if row["topic"] == "robot/state")
    assert state["key"] == "test/robot/state" and state["writers"] == ["pub"]
    info = json.loads(cli("topic", "info", "control/goal", "--profile", str(running_pub)).stdout)
    assert info["type"] == "Goal" and "task" in info["schema"]["properties"]
    with query.Target.from_profile(running_pub).open() as session:
        received: list[bytes] = []
        session.declare_subscriber(
            "test/world/obstacles", lambda sample: received.append(sample.payload.to_bytes())
        )
        result = cli(
            "topic",
            "pub",
            "world/obstacles",
            '{"circles": [{"x": 2, "y": 0, "radius": 0.1}]}',
            "--profile",
            str(running_pub),
        )
        assert result.returncode == 0, result.stderr
        assert json.loads(result.stdout)["published"] == 1
        assert "warning" not in result.stderr  # no component of the profile writes it
        deadline = time.monotonic() + 10.0
        while not received:
            assert time.monotonic() < deadline, "the published message did not arrive"
            time.sleep(0.01)
    bad = cli("topic", "pub", "control/goal", '{"task": "pose"}', "--profile", str(running_pub))
    assert bad.returncode == 2 and "a pose task needs a pose" in bad.stderr


def test_topic_echo_gives_up_at_its_timeout_on_a_silent_topic(running_pub: Path) -> None:
    """Nothing writes world/obstacles here: echo says so and exits 1, instead of waiting on."""
    result = cli(
        "topic", "echo", "world/obstacles", "--timeout", "1", "--profile", str(running_pub)
    )
    assert result.returncode == 1, result.stderr
    assert result.stdout == ""
    assert "no message in 1 s on test/world/obstacles" in result.stderr
    helped = cli("topic", "echo", "--help")
    assert "--timeout S" in helped.stdout and "no message in S s" in helped.stdout


def test_topic_echo_counts_its_timeout_from_the_last_message(running_pub: Path) -> None:
    """A live topic within the timeout is echoed to its count and exits 0."""
    result = cli(
        "topic",
        "echo",
        "robot/state",
        "--count",
        "2",
        "--timeout",
        "30",
        "--profile",
        str(running_pub),
    )
    assert result.returncode == 0, result.stderr
    assert len(result.stdout.splitlines()) == 2


def test_topic_pub_warns_when_a_running_component_writes_the_topic(running_pub: Path) -> None:
    """pub writes control/goal in this profile: what the user publishes there is replaced by
    its next goal, and the user is told so."""
    result = cli(
        "topic",
        "pub",
        "control/goal",
        '{"task": "position", "position": [0.5, 0, 0.4]}',
        "--profile",
        str(running_pub),
    )
    assert result.returncode == 0, result.stderr
    assert "warning: pub writes test/control/goal in this profile and is running" in result.stderr
    assert json.loads(result.stdout)["live_writers"] == ["pub"]


def test_goal_goes_to_control_goal_where_no_supervisor_takes_requests(running_pub: Path) -> None:
    """Nothing reads goal/request here: the goal goes to control/goal, stamped on the wall
    clock of this profile, and the user is told that pub writes it too."""
    sent: list[Goal] = []
    arrived = threading.Event()

    def on_goal(sample: zenoh.Sample) -> None:
        goal = codec.decode(sample.payload.to_bytes(), Goal)
        if goal.header.source == "parsimony":
            sent.append(goal)
            arrived.set()

    with query.Target.from_profile(running_pub).open() as session:
        session.declare_subscriber("test/control/goal", on_goal)
        before = time.time_ns()
        result = cli(
            "goal", "0.5", "0", "0.4", "--yaw", "90", "--json", "--profile", str(running_pub)
        )
        assert result.returncode == 0, result.stderr
        assert arrived.wait(10.0), "the goal did not arrive"
    assert json.loads(result.stdout)["topic"] == "control/goal"
    assert "warning: pub writes test/control/goal" in result.stderr
    (goal,) = sent
    assert before <= goal.header.stamp_ns <= time.time_ns()
    expected = dq.pose(dq.rotation_quaternion(math.pi / 2, dq.K_[1:]), np.array([0.5, 0, 0.4]))
    assert goal.task == "pose" and np.allclose(goal.pose, expected, atol=1e-12)


def test_param_list_describe_dump_and_load(running_pub: Path, tmp_path: Path) -> None:
    profile = str(running_pub)
    values = json.loads(cli("param", "list", "pub", "--json", "--profile", profile).stdout)
    assert {"rate_hz", "goal_task", "goal_z", "q5"} <= values.keys()
    with query.Target.from_profile(running_pub).open() as session:
        assert values["rate_hz"] == query.get_param(session, "test", "pub", "rate_hz")
    described = json.loads(
        cli("param", "describe", "pub", "rate_hz", "--json", "--profile", profile).stdout
    )
    assert described == [
        {
            "name": "rate_hz",
            "type": "float",
            "default": 10.0,
            "low": 0.1,
            "high": 1000.0,
            "choices": None,
            "doc": "publishing rate",
        }
    ]
    dump = cli("param", "dump", "pub", "--profile", profile)
    assert dump.returncode == 0 and yaml.safe_load(dump.stdout) == values
    saved = tmp_path / "pub.yaml"
    saved.write_text(yaml.safe_dump({**values, "goal_z": values["goal_z"] + 0.25}))
    loaded = cli("param", "load", "pub", str(saved), "--profile", profile)
    assert loaded.returncode == 0, loaded.stderr
    now = json.loads(cli("param", "list", "pub", "--json", "--profile", profile).stdout)
    assert now == {**values, "goal_z": values["goal_z"] + 0.25}
    saved.write_text("rate_hz: -1\n")
    refused = cli("param", "load", "pub", str(saved), "--profile", profile)
    assert refused.returncode == 1
    assert "rate_hz: expected a float in [0.1, 1000.0]" in refused.stderr


def test_node_info_shows_what_a_component_reads_writes_and_counts(running_pub: Path) -> None:
    wait_for_first_message(running_pub)
    result = cli("node", "info", "pub", "--json", "--profile", str(running_pub))
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    assert info["module"] == "components.scripted_publisher" and info["state"] == "running"
    assert info["reads"] == [] and info["writes"] == ["robot/state", "control/goal"]
    assert info["counters"]["published.robot/state"] > 0
    assert info["parameters"]["rate_hz"] > 0


def test_topic_echo_started_in_the_background_stops_on_sigint(running_pub: Path) -> None:
    """Started as a shell's background job (SIGINT ignored, inherited), echo on a silent topic
    still stops at Ctrl-C's signal, and exits 0 with nothing on stdout."""
    echo = background_job("topic", "echo", "world/obstacles", "--profile", str(running_pub))
    said = StderrLines(echo)
    said.wait_for("waiting for messages on test/world/obstacles")
    assert stopped_by(echo, signal.SIGINT) == 0, said.all()
    assert echo.stdout is None or echo.stdout.read() == ""
