"""`parsimony status` on a launched system: a short line per component by default, every
counter on demand (before, 20 or more unexplained counters per component on one line)."""

from __future__ import annotations

import argparse
import json
import time
from typing import TYPE_CHECKING

import pytest

from deploy import ROBOT_FILE, query
from messages import topics
from messages.header import Header
from messages.status import ComponentStatus
from parsimony.commands import status

if TYPE_CHECKING:
    from tests.deploy.conftest import LaunchFixture, ProfileWriter


def command(*argv: str) -> int:
    root = argparse.ArgumentParser(prog="parsimony")
    status.add_parser(root.add_subparsers())
    return status.run(root.parse_args(["status", *argv]))


def test_status_summarises_each_component_and_lists_every_counter_on_demand(
    write_profile: ProfileWriter, launch: LaunchFixture, capsys: pytest.CaptureFixture[str]
) -> None:
    """A controller fed by a scripted publisher, and one malformed state sent to it."""
    pub = {"name": "pub", "module": "scripted_publisher", "role": "tool",
           "params": {"rate_hz": 50.0}}  # fmt: skip
    ctl = {"name": "ctl", "module": "lp_controller", "role": "controller"}
    profile = write_profile([pub, ctl], robot=str(ROBOT_FILE))
    launched = launch(profile)
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
    assert header.split() == ["NAME", "MODULE", "STATE", "PID", "IN", "OUT", "CPU", "S",
                              "FAULTS", "(non-zero)"]  # fmt: skip
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
    launched.stop()


def test_a_components_faults_are_told_apart_from_its_other_counters() -> None:
    counters = {"received.robot/state": 7, "received.control/goal": 3, "published.x": 5,
                "overwritten.robot/state": 4, "clock_stalls": 1, "errors.timer.t": 0,
                "port_errors": 2, "handler.robot/state_us_p99": 900, "cpu_ms": 2500}  # fmt: skip
    found = ComponentStatus(header=Header(stamp_ns=0, frame="", seq=0, source="drv"), name="drv",
                            module="base_driver", state="no port", pid=12, counters=counters)
    (line,) = status.format_table([("drv", found)]).splitlines()[1:]
    assert line.split() == ["drv", "base_driver", "no", "port", "12", "10", "5", "2.5",
                            "clock_stalls=1", "port_errors=2"]  # fmt: skip
