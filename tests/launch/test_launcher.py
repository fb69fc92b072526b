"""`parsimony launch` as a real process tree on loopback: start, restart, stop, exit codes."""

from __future__ import annotations

import os
import re
import signal
import time
from pathlib import Path
from typing import TYPE_CHECKING

import yaml

from launch import query
from profiles.deploy_files import ROBOT_FILE
from profiles.profile import Profile
from tests.launch.conftest import DEADLINE_S, free_port, publisher
from tests.processes import process_gone

if TYPE_CHECKING:
    from tests.launch.conftest import LaunchFixture, ProfileWriter


def test_a_killed_component_comes_back_at_once_then_after_a_backoff_until_restarts_run_out(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    launched = launch(
        write_profile([publisher("pub", restart={"backoff_initial_s": 0.1, "max_restarts": 2})])
    )
    started, _, match = launched.wait_for(r"\[launch\] started pub \(.*pid (\d+)\)")
    launched.wait_for(r"\[launch\] pub alive", after=started)
    os.kill(int(match.group(1)), signal.SIGKILL)
    # The first restart waits for nothing: a driver that died stops its robot as it comes back.
    exited, _, _ = launched.wait_for(r"\[launch\] pub exited with -9; restart 1/2 in 0\.0 s")
    restarted, _, match = launched.wait_for(r"\[launch\] started pub \(.*pid (\d+)\)", exited)
    launched.wait_for(r"\[launch\] pub alive", after=restarted)

    os.kill(int(match.group(1)), signal.SIGKILL)
    exited, _, _ = launched.wait_for(r"\[launch\] pub exited with -9; restart 2/2 in 0\.1 s")
    restarted, _, match = launched.wait_for(r"\[launch\] started pub \(.*pid (\d+)\)", exited)
    launched.wait_for(r"\[launch\] pub alive", after=restarted)
    os.kill(int(match.group(1)), signal.SIGKILL)
    launched.wait_for(r"\[launch\] pub exited with -9; no restarts left \(2/2\)")
    launched.wait_for(r"\[launch\] stopping \(no component left running\)")
    assert launched.process.wait(DEADLINE_S) == 1
    assert "[launch] failed: pub" in launched.text()


def test_sigint_stops_in_reverse_role_order_and_every_line_says_when_and_what(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    """Started drivers first, stopped tools first; a clean stop exits 0. (A failure's exit
    code is checked by the restart and start-up tests.) The launcher's lines and its
    components' alike say when and who, and it says what it waits for. (One launch for both:
    each stamped line was the same of a launch of its own.)"""
    slow = {"params": {"rate_hz": 1.0}}  # states and goals the controller need not solve for
    profile = write_profile(
        [
            publisher("arm", role="tool", **slow),
            {"name": "lp", "module": "lp_controller", "role": "controller"},
            publisher("est", role="estimator", **slow),
            publisher("base", role="driver", **slow),
        ],
        robot=str(ROBOT_FILE),
    )
    launched = launch(profile)
    timeout = Profile.model_fields["startup_timeout_s"].default
    launched.wait_for(
        rf"\[launch\] waiting for 4 component\(s\) to come alive \(at most {timeout:g} s\)"
    )
    launched.wait_for(r"\[launch\] all 4 components alive; running until Ctrl-C")

    assert launched.stop(signal.SIGINT) == 0
    text = launched.text()
    starts = [text.index(f"[launch] started {name} ") for name in ("base", "est", "lp", "arm")]
    stops = [text.index(f"[launch] {name} stopped (0)") for name in ("arm", "lp", "est", "base")]
    assert starts == sorted(starts) and stops == sorted(stops)
    assert "INFO arm stopping on SIGTERM" in text
    assert " lost" not in text  # a clean stop says "stopped", not "lost" (it did both)
    stamped = re.compile(r"^\d\d:\d\d:\d\d\.\d{3} \[(launch|arm|lp|est|base)\] ")
    assert [line for line in text.splitlines() if not stamped.match(line)] == []
    assert " [arm] INFO arm running" in text


def test_a_component_starts_once_those_it_waits_for_are_alive_and_stops_before_them(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    """An emulated device's driver waits for the emulator (before, a driver opened a device
    that did not exist yet and said so at every start)."""
    profile = write_profile(
        [publisher("drv", role="driver", after=["emu"]), publisher("emu", role="driver")]
    )
    launched = launch(profile)
    waits, _, _ = launched.wait_for(r"\[launch\] drv starts once emu alive")
    alive, _, _ = launched.wait_for(r"\[launch\] emu alive")
    started, _, _ = launched.wait_for(r"\[launch\] started drv ")
    assert waits < alive < started
    launched.wait_for(r"\[launch\] all 2 components alive", after=started)
    assert launched.stop() == 0
    text = launched.text()
    assert text.index("[launch] drv stopped (0)") < text.index("INFO emu stopping on SIGTERM")


def test_a_change_of_a_components_state_is_said(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    """On simulated time with no simulator, a component waits for the clock's first tick: the
    launcher says so (and not that a clock stalled which never started)."""
    profile = write_profile([publisher("pub")], clock="sim", clock_timeout_s=0.2)
    launched = launch(profile)
    alive, _, _ = launched.wait_for(r"\[launch\] pub alive")
    launched.wait_for(r"\[launch\] pub waiting for the clock \(was running\)", after=alive)
    assert launched.stop() == 0


def stamp_s(line: str) -> float:
    """The launcher's own time of one of its lines (HH:MM:SS.mmm), in seconds of the day."""
    hours, minutes, seconds = line.split(" ", 1)[0].split(":")
    return 3600 * int(hours) + 60 * int(minutes) + float(seconds)


def test_duration_counts_from_every_component_alive_and_ends_the_launch_cleanly(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    """However long the start-up takes (a loaded machine, a slow import), the system runs the
    whole duration: before, it counted from the launch, and a component alive late ran less
    or was stopped before its handler was set."""
    launched = launch(write_profile([publisher("pub")]), "--duration", "1.5")
    assert launched.process.wait(DEADLINE_S) == 0
    alive, _, _ = launched.wait_for(
        r"\[launch\] all 1 components alive; running until the end of the 1\.5 s duration"
    )
    stop, _, _ = launched.wait_for(r"\[launch\] stopping \(end of duration\)", after=alive)
    launched.wait_for(r"\[launch\] pub stopped \(0\)", after=stop)
    lines = launched.text().splitlines()
    ran_s = (stamp_s(lines[stop]) - stamp_s(lines[alive])) % 86400  # past midnight too
    assert ran_s >= 1.5 - 0.001, ran_s  # the stamps are to the millisecond


def test_the_launcher_warns_of_a_topic_read_and_never_written(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    """A controller alone waits for robot/state that nothing in the profile publishes."""
    controller = {"name": "ctl", "module": "lp_controller", "role": "controller"}
    profile = write_profile([controller], robot=str(ROBOT_FILE))
    launched = launch(profile, "--duration", "1.0")
    launched.wait_for(
        r"^\d\d:\d\d:\d\d\.\d{3} \[launch\] warning: test/robot/state is read "
        r"by ctl and written by no component"
    )
    assert launched.process.wait(DEADLINE_S) == 0
    assert "test/base/command is read" not in launched.text()


def test_a_component_that_never_comes_alive_fails_the_launch_by_name(
    write_profile: ProfileWriter, launch: LaunchFixture, tmp_path: Path
) -> None:
    """Its session connects to a port nobody listens on: it runs, but the router never sees
    it. Before, the launch ran on and exited 0."""
    profile = write_profile([publisher("pub")], startup_timeout_s=2.0)
    data = yaml.safe_load(profile.read_text())
    data["zenoh"]["connect"] = [f"tcp/127.0.0.1:{free_port()}"]
    profile.write_text(yaml.safe_dump(data))
    launched = launch(profile)
    launched.wait_for(r"\[launch\] stopping \(start-up failed: pub not alive after 2\.0 s")
    assert launched.process.wait(DEADLINE_S) == 1
    assert "[launch] failed: pub" in launched.text()


def test_a_configuration_error_at_start_up_fails_the_whole_launch(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    """One component cannot start with what it was given (exit 2: a recorder whose file
    cannot be made, which no check of the profile can know): the others are stopped, the
    launch fails, instead of running on without it."""
    bad = {
        "name": "bad",
        "module": "recorder",
        "role": "tool",
        "params": {"path": "/dev/null/session.mcap"},
    }
    launched = launch(write_profile([publisher("good"), bad]))
    launched.wait_for(r"\[launch\] bad exited with 2; configuration error, not restarting")
    launched.wait_for(r"\[launch\] stopping \(start-up failed: bad failed during start-up\)")
    assert launched.process.wait(DEADLINE_S) == 1
    launched.wait_for(r"\[launch\] good stopped")


def test_a_hung_component_is_restarted_by_the_watchdog_with_its_parameters_set_at_run_time(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    """SIGSTOP leaves the process and its session up but answering nothing: before, it was
    reported lost only after the ~10 s session lease and never restarted. A parameter set
    before: its restart has it. Then the launcher is killed: its fork server ends, and the
    component, the server's child, stops by itself.
    (One launch for what two proved: the parameter's component was killed by the test.)"""
    profile = write_profile([publisher("pub")], watchdog_s=1.0)
    launched = launch(profile)
    started, _, match = launched.wait_for(r"\[launch\] started pub \(.*pid (\d+)\)")
    launched.wait_for(r"\[launch\] pub alive", after=started)
    target = query.Target.from_profile(profile)
    with target.open() as session:
        assert query.set_param(session, "test", "pub", "rate_hz", "7.5") == 7.5
        stopped_at = time.monotonic()
        os.kill(int(match.group(1)), signal.SIGSTOP)
        hung, hung_at, _ = launched.wait_for(r"\[launch\] pub hung: no status answer for")
        assert hung_at - stopped_at < 3.0
        launched.wait_for(r"\[launch\] pub exited with -9; restart 1/5", after=hung)
        restarted, _, match = launched.wait_for(r"\[launch\] started pub \(.*pid (\d+)\)", hung)
        launched.wait_for(r"\[launch\] pub alive", after=restarted)
        assert query.get_param(session, "test", "pub", "rate_hz") == 7.5
        assert query.get_param(session, "test", "pub", "goal_task") == "position"  # untouched
    pid = int(match.group(1))
    # Forked by the launch's fork server, no interpreter of its own (launch/fork_server.py).
    server = int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    assert server != launched.process.pid
    command = Path(f"/proc/{pid}/cmdline").read_bytes()
    assert command == Path(f"/proc/{server}/cmdline").read_bytes()
    launched.process.kill()
    launched.process.wait()
    deadline = time.monotonic() + DEADLINE_S
    while not (process_gone(pid) and process_gone(server)):
        assert time.monotonic() < deadline, "a process outlived its launcher by 60 s"
        time.sleep(0.02)


def test_an_invalid_profile_is_refused_before_anything_starts(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    launched = launch(write_profile([publisher("pub", restart={"policy": "sometimes"})]))
    assert launched.process.wait(DEADLINE_S) == 2
    text = launched.text()
    assert "components[0].restart.policy" in text and "'on-failure'" in text
    assert "started" not in text
