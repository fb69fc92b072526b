"""`parsimony status` on a launched system: a short line per component by default, every
counter on demand (before, 20 or more unexplained counters per component on one line); a
misspelt profile or an unreachable router said in one line."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from launch import query
from messages import topics
from messages.header import Header
from messages.status import ComponentStatus
from parsimony.commands import status
from profiles.deploy_files import ROBOT_FILE
from profiles.endpoints import free_port
from tests.parsimony.cli_process import run_cli

if TYPE_CHECKING:
    from tests.launch.conftest import LaunchFixture, ProfileWriter


def command(*argv: str) -> int:
    root = argparse.ArgumentParser(prog="parsimony")
    status.add_parser(root.add_subparsers())
    return status.run(root.parse_args(["status", *argv]))


def test_status_waits_for_the_launch_then_summarises_each_component_and_every_counter(
    write_profile: ProfileWriter, launch: LaunchFixture, capsys: pytest.CaptureFixture[str]
) -> None:
    """As the README's first hour runs it: the launch in the background, `status --wait` at
    once; it says what it waits for (the router first), then prints the status. Then a
    controller fed by a scripted publisher, and one malformed state sent to it: a short line
    per component, every counter on demand. (One launch for what two launches proved.)"""
    pub = {
        "name": "pub",
        "module": "scripted_publisher",
        "role": "tool",
        "params": {"rate_hz": 50.0},
    }
    ctl = {"name": "ctl", "module": "lp_controller", "role": "controller"}
    profile = write_profile([pub, ctl], robot=str(ROBOT_FILE))
    waiting = subprocess.Popen(
        [sys.executable, "-m", "parsimony.cli", "status", str(profile), "--wait"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert waiting.stderr is not None
        first = waiting.stderr.readline()  # before the launch: nothing listens yet
        assert first.startswith(f"status: waiting for the router at {router_of(profile)}"), first
        launched = launch(profile)
        out, err = waiting.communicate(timeout=120.0)  # a safety net: --wait ends in 60 s
    finally:
        waiting.kill()
    assert waiting.returncode == 0, first + err
    waited = {line.split()[0]: line.split() for line in out.splitlines()[1:]}
    assert waited["pub"][2] == waited["ctl"][2] == "running"
    assert "status: all 2 components alive" in err

    launched.wait_for(r"\[launch\] all 2 components alive")
    with query.Target.from_profile(profile).open() as session:
        deadline = time.monotonic() + 10.0
        while True:  # until the refusal is counted (a put may go before the route is known)
            session.put(topics.ROBOT_STATE.key("test"), b"not a robot state")
            found = query.statuses(session, "test")
            counters = found["ctl"].counters if "ctl" in found else {}
            if counters.get("rejected.robot/state") and counters.get("received.robot/state"):
                break
            assert time.monotonic() < deadline, found
    capsys.readouterr()

    assert command(str(profile)) == 0
    out, err = capsys.readouterr()
    header, *rows = out.splitlines()
    assert header.split() == [
        "NAME",
        "MODULE",
        "STATE",
        "PID",
        "IN",
        "OUT",
        "CPU",
        "S",
        "FAULTS",
        "(non-zero)",
    ]
    row = {line.split()[0]: line.split() for line in rows}
    assert row["ctl"][:3] == ["ctl", "lp_controller", "running"]
    assert int(row["ctl"][4]) > 0 and int(row["pub"][5]) > 0  # messages in, messages out
    assert "rejected.robot/state" in [cell.split("=")[0] for cell in row["ctl"][7:]]
    assert "published." not in out and "handler." not in out  # the rest is behind --counters
    assert "--counters lists every counter" in err

    assert command(str(profile), "--counters") == 0
    every = capsys.readouterr().out
    listed = every.split("\nctl\n", 1)[1].split("\n\n", 1)[0]
    names = [line.split()[0] for line in listed.splitlines()]
    assert set(names) >= set(counters) - {"cpu_ms"} and "published.base/command" in names

    assert command(str(profile), "--json") == 0
    rows_json = {r["name"]: r for r in json.loads(capsys.readouterr().out)}
    assert set(rows_json["ctl"]["status"]["counters"]) >= set(counters)
    assert launched.stop() == 0


def test_a_components_faults_are_told_apart_from_its_other_counters() -> None:
    counters = {
        "received.robot/state": 7,
        "received.control/goal": 3,
        "published.x": 5,
        "overwritten.robot/state": 4,
        "clock_stalls": 1,
        "errors.timer.t": 0,
        "port_errors": 2,
        "handler.robot/state_us_p99": 900,
        "cpu_ms": 2500,
    }
    found = ComponentStatus(
        header=Header(stamp_ns=0, frame="", seq=0, source="drv"),
        name="drv",
        module="base_driver",
        state="no port",
        pid=12,
        counters=counters,
    )
    (line,) = status.format_table([("drv", found)]).splitlines()[1:]
    assert line.split() == [
        "drv",
        "base_driver",
        "no",
        "port",
        "12",
        "10",
        "5",
        "2.5",
        "clock_stalls=1",
        "port_errors=2",
    ]


def test_status_wait_names_the_components_that_never_come(
    running_pub: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """pub is alive; the profile also has a ghost, which nothing launched. And with no router
    at all, every component is named."""
    ghost = tmp_path / "ghost.yaml"
    ghost.write_text(
        f"extends: {running_pub}\ncomponents:\n"
        "  - {name: ghost, module: scripted_publisher, role: tool}\n"
    )
    assert command(str(ghost), "--wait", "--timeout", "0.5") == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert err.splitlines()[-1] == "not alive after 0.5 s: ghost (1 of 2 alive)"

    nowhere = tmp_path / "nowhere.yaml"
    router = f"tcp/127.0.0.1:{free_port()}"
    nowhere.write_text(f"extends: {ghost}\nzenoh: {{router: ['{router}']}}\n")
    assert command(str(nowhere), "--wait", "--timeout", "0.5") == 1
    assert capsys.readouterr().err.splitlines()[-1] == (
        f"no router at {router} after 0.5 s (is the profile launched?); not alive: pub, ghost"
    )


def router_of(profile: Path) -> str:
    return query.Target.from_profile(profile).zenoh.router[0]


def test_status_of_a_misspelt_profile_says_the_file_does_not_exist():
    result = run_cli("status", "deploy/controlers.yaml")
    assert result.returncode == 2
    assert "deploy/controlers.yaml: no such profile file" in result.stderr


def test_zenoh_errors_reach_the_user_as_one_readable_line():
    result = run_cli("status", "test", "--router", "tcp/127.0.0.1:1", "--timeout", "0.5")
    assert result.returncode == 2
    assert "cannot reach a router at tcp/127.0.0.1:1" in result.stderr
    assert ".rs:" not in result.stderr and len(result.stderr.strip().splitlines()) == 1
