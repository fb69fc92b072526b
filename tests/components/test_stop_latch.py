"""The latched emergency stop (``components.stop_latch``), in process on a real router: the
stop and the release from the command line, a holder started later starting stopped, the
status saying it, who may release, and the base driver on a pseudo-terminal refusing to
move while stopped."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
import yaml
import zenoh

from components.base_driver import BaseDriver
from components.runtime import Node
from components.stop_latch import StopLatch, stop_state
from launch import query
from messages import codec, topics
from messages.commands import BaseCommand
from messages.header import Header
from messages.process import RUNTIME_DIR_ENV
from parsimony import cli
from protocols import create_oi
from tests.components.conftest import System
from tests.components.driver_harness import FakeLink, driver_system

USER = "alice"


def give(system: System, capsys: pytest.CaptureFixture[str], command: str, *more: str) -> dict:
    """`parsimony stop` or `release` on the system, in process; its JSON."""
    capsys.readouterr()
    code = cli.main([command, "--profile", str(system.path), "--json", *more])
    assert code == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def test_a_stop_holds_until_its_release_and_a_holder_started_meanwhile_starts_stopped(
    system: System, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("PARSIMONY_USER", USER)
    with Node(system.profile, "talker") as talker:
        first = StopLatch(talker)
        talker.start()
        assert not first.stopped
        given = give(system, capsys, "stop", "--reason", "a hand in the way")
        assert given["stopped"] and given["header"]["source"] == USER
        assert set(given["holders"]) == {"talker"}
        assert first.stopped and first.state.reason == "a hand in the way"
        status = query.statuses(system.router, system.profile.namespace)["talker"]
        assert status.state == f"running, stopped by {USER}" and status.stop == first.state
        assert not first.take(
            stop_state(False, "late").model_copy(
                update={"header": Header(stamp_ns=1, frame="", seq=0, source="late")}
            )
        )  # older than the stop: ignored
        with Node(system.profile, "listener") as listener:
            second = StopLatch(listener)  # a restarted component asks before it moves
            assert second.stopped and second.state == first.state
            listener.start()
            released = give(system, capsys, "release")
            assert set(released["holders"]) == {"talker", "listener"}
            assert not first.stopped and not second.stopped
            assert first.state.header.source == USER


def test_only_who_may_command_the_robot_may_release(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "credentials.txt").write_text("operator:a\nviewer:b\npub:c\n")
    profile = {
        "namespace": "test",
        "zenoh": {
            "mode": "client",
            "router": ["tcp/127.0.0.1:9"],
            "access": {
                "credentials": "credentials.txt",
                "writers": {"control/goal": ["operator"]},
            },
        },
        "components": [{"name": "pub", "module": "scripted_publisher", "role": "tool"}],
    }
    path = tmp_path / "access.yaml"
    path.write_text(yaml.safe_dump(profile))
    monkeypatch.setenv("PARSIMONY_USER", "viewer")
    assert cli.main(["release", "--profile", str(path)]) == 1
    assert capsys.readouterr().err.strip() == (
        "viewer may not release the stop: not a writer of control/goal (zenoh.access)"
    )


def test_the_base_driver_stops_at_once_and_refuses_motion_until_the_release(
    deployed, tmp_path: Path, wait_until
) -> None:
    link = FakeLink(tmp_path / "create2")
    system = driver_system(deployed, tmp_path, "base_driver", link.link)
    namespace = system.profile.namespace
    command = system.router.declare_publisher(topics.BASE_COMMAND.key(namespace))
    stop = system.router.declare_publisher(topics.CONTROL_STOP.key(namespace))
    heard = bytearray()
    moving = create_oi.drive_direct(100, 100)

    def drive() -> None:
        header = Header(stamp_ns=time.time_ns(), frame="base", seq=0, source="test")
        wheels = {"left_wheel": 0.1, "right_wheel": 0.1}
        message = BaseCommand(header=header, forward_velocity=0.1, angular_velocity=0, **wheels)
        command.put(codec.encode(message))

    def hears(expected: bytes) -> bool:
        heard.extend(link.read())
        return expected in heard

    with Node(
        system.profile, "base_driver", BaseDriver.params, BaseDriver.reads, BaseDriver.writes
    ) as node:
        driver = BaseDriver(node)
        node.start(driver.shutdown)
        wait_until(lambda: drive() or hears(moving), "the wheels driven")
        stop.put(codec.encode(stop_state(True, USER)))
        wait_until(lambda: driver.latch.stopped, "the stop taken")
        wait_until(
            lambda: (
                hears(moving + create_oi.drive_direct(0, 0))
                or heard.rfind(create_oi.drive_direct(0, 0)) > heard.rfind(moving)
            ),
            "the wheels stopped",
        )
        stopped_at = len(heard)

        def taken() -> int:
            return sum(node.counters[f"{k}.base/command"] for k in ("received", "overwritten"))

        before = taken()
        for _ in range(20):  # a controller still sending
            drive()
        wait_until(lambda: taken() >= before + 20, "the commands taken")
        assert node.counters["refused_while_stopped"] >= 1
        heard.extend(link.read())
        assert moving not in heard[stopped_at:]
        stop.put(codec.encode(stop_state(False, USER)))
        wait_until(lambda: not driver.latch.stopped, "the release taken")
        del heard[:]
        wait_until(lambda: drive() or hears(moving), "the wheels driven again")
    link.close()


def test_the_stop_outlives_its_router(
    system: System, capsys: pytest.CaptureFixture[str], wait_until
) -> None:
    """The router goes away and comes back (its port the same): the holder kept the stop, and
    a holder started after hears it (asked, or put again every second)."""
    with Node(system.profile, "talker") as talker:
        first = StopLatch(talker)
        talker.start()
        give(system, capsys, "stop")
        system.router.close()
        assert first.stopped and talker.status().stop == first.state
        with zenoh.open(system.profile.zenoh.router_config()) as router:
            system.router = router  # the fixture's, closed once more at its end: no harm
            with Node(system.profile, "listener") as listener:
                second = StopLatch(listener)
                listener.start()
                wait_until(lambda: second.stopped, "the stop heard after the router's return")
                assert second.state == first.state


def test_a_driver_restarted_while_the_router_is_away_starts_stopped(
    deployed, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, wait_until
) -> None:
    """The stop kept on disk by the holders of a launch (``kept_dir``): the base driver took a
    stop, died, and starts again with no router to ask: it starts stopped and stops the wheels;
    the router back, the release releases it."""
    launch = tmp_path / "launch"  # the launcher's runtime directory
    launch.mkdir()
    monkeypatch.setenv(RUNTIME_DIR_ENV, str(launch))
    link = FakeLink(tmp_path / "create2")
    system = driver_system(deployed, tmp_path, "base_driver", link.link)
    namespace = system.profile.namespace
    spec = (system.profile, "base_driver", BaseDriver.params, BaseDriver.reads, BaseDriver.writes)
    with Node(*spec) as node:
        driver = BaseDriver(node)
        node.start(driver.shutdown)
        stop = system.router.declare_publisher(topics.CONTROL_STOP.key(namespace))
        stop.put(codec.encode(stop_state(True, USER, "a hand in the way")))
        kept = launch / "stop" / "base_driver.json"
        wait_until(kept.exists, "the stop kept on disk")
        given = driver.latch.state
    system.router.close()  # the router away: nobody to ask
    link.read()
    with Node(*spec) as node:
        driver = BaseDriver(node)
        assert driver.latch.stopped and driver.latch.state == given
        node.start(driver.shutdown)
        assert node.status().stop == given
        heard = bytearray()
        wait_until(
            lambda: heard.extend(link.read()) or node.counters["stops"] >= 1, "the wheels stopped"
        )
        heard.extend(link.read())
        assert heard.endswith(create_oi.drive_direct(0, 0))
        with zenoh.open(system.profile.zenoh.router_config()) as router:
            system.router = router  # the fixture's, closed once more at its end: no harm
            release = router.declare_publisher(topics.CONTROL_STOP.key(namespace))
            wait_until(
                lambda: (
                    release.put(codec.encode(stop_state(False, USER))) or not driver.latch.stopped
                ),
                "the release heard after the router's return",
            )
    link.close()


def test_a_kept_stop_that_cannot_be_read_starts_the_holder_stopped(
    system: System, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, wait_until
) -> None:
    """Fail safe: what a holder cannot read may have been a stop; the first release given
    replaces it."""
    launch = tmp_path / "launch"
    (launch / "stop").mkdir(parents=True)
    (launch / "stop" / "talker.json").write_text('{"stopped": tr')
    monkeypatch.setenv(RUNTIME_DIR_ENV, str(launch))
    with Node(system.profile, "talker") as talker:
        latch = StopLatch(talker)
        talker.start()
        assert latch.stopped and latch.state.header.source == "stop_latch"
        assert "talker.json unreadable" in latch.state.reason
        release = system.router.declare_publisher(topics.CONTROL_STOP.key("test"))
        release.put(codec.encode(stop_state(False, USER)))
        wait_until(lambda: not latch.stopped, "the release taken")
        kept = launch / "stop" / "talker.json"
        wait_until(lambda: '"stopped":false' in kept.read_text(), "the release kept")
