"""`parsimony status` and `parsimony param` against a launched system on loopback."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

from deploy import query
from parsimony.commands import param, status


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
    assert "published.robot/state=" in table[1]

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
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    (row,) = json.loads(result.stdout)
    assert row["name"] == "pub"


def test_status_of_an_empty_namespace_or_a_remote_router_fails(
    running_pub: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    router = status.target_of(argparse.Namespace(profile=running_pub, target=None)).zenoh.router[0]
    assert command(status, "status", "nobody", "--router", router, "--timeout", "0.5") == 1
    assert "no live component in namespace 'nobody'" in capsys.readouterr().err
    assert command(status, "status", "test", "--router", "tcp/10.1.2.3:7447") == 1
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
    monkeypatch.setenv(param.PROFILE_ENV, str(running_pub))
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
