"""`parsimony launch` of a profile whose components share a process (``processes: shared``)."""

from __future__ import annotations

import os
import signal
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from launch import query
from profiles.profile import ProfileError, load_profile
from tests.launch.conftest import publisher

if TYPE_CHECKING:
    from tests.launch.conftest import LaunchFixture, ProfileWriter

STARTED = r"\[launch\] started base, est, arm in one process \(components\.container, pid (\d+)\)"


def test_shared_components_run_in_one_process_restart_together_and_stop_in_order(
    write_profile: ProfileWriter, launch: LaunchFixture
) -> None:
    """One process for the three (their statuses say its pid), each alive and reported by name;
    that process killed, each is restarted by its policy, together, with the parameter set on
    one of them kept; SIGINT stops them tools first, and the launch exits 0."""
    profile = write_profile(
        [publisher("arm"), publisher("est", role="estimator"), publisher("base", role="driver")],
        processes="shared",
    )
    launched = launch(profile)
    started, _, match = launched.wait_for(STARTED)
    for name in ("base", "est", "arm"):
        launched.wait_for(rf"\[launch\] {name} alive", after=started)
    pid = int(match.group(1))
    target = query.Target.from_profile(profile)
    with target.open() as session:
        found = query.statuses(session, "test")
        assert {name: status.pid for name, status in found.items()} == dict.fromkeys(
            ("arm", "est", "base"), pid
        )
        assert query.set_param(session, "test", "est", "rate_hz", "7.5") == 7.5
        os.kill(pid, signal.SIGKILL)
        for name in ("base", "est", "arm"):
            launched.wait_for(rf"\[launch\] {name} exited with -9; restart 1/5", after=started)
        restarted, _, match = launched.wait_for(STARTED, after=started + 1)
        assert int(match.group(1)) != pid
        for name in ("base", "est", "arm"):
            launched.wait_for(rf"\[launch\] {name} alive", after=restarted)
        assert query.get_param(session, "test", "est", "rate_hz") == 7.5
        assert query.get_param(session, "test", "arm", "rate_hz") == 20.0
    assert launched.stop(signal.SIGINT) == 0
    text = launched.text()
    stops = [text.index(f"[launch] {name} stopped (0)") for name in ("arm", "est", "base")]
    assert stops == sorted(stops)
    assert " lost" not in text.split("[launch] stopping")[-1]


def test_a_bad_processes_value_is_refused_naming_the_field(tmp_path: Path) -> None:
    path = tmp_path / "profile.yaml"
    path.write_text(
        "namespace: test\nprocesses: together\n"
        "components: [{name: pub, module: scripted_publisher, role: tool}]\n"
    )
    with pytest.raises(ProfileError, match=r"processes: Input should be 'separate' or 'shared'"):
        load_profile(path)


def test_the_shared_process_loads_its_modules_while_the_recorder_starts(
    write_profile: ProfileWriter, launch: LaunchFixture, tmp_path: Path
) -> None:
    """With a recorder, the components sharing a process start once it is alive, in the process
    started before it (its modules loaded meanwhile), not in one started then."""
    profile = write_profile(
        [publisher("arm"), publisher("est", role="estimator")], processes="shared"
    )
    launched = launch(profile, "--record", str(tmp_path / "session.mcap"))
    _, _, recorder = launched.wait_for(r"\[launch\] started recorder \(.*, pid (\d+)\)")
    _, _, shared = launched.wait_for(r"\[launch\] started est, arm in one process .*pid (\d+)\)")
    started = [_start_ticks(int(found.group(1))) for found in (shared, recorder)]
    assert started == sorted(started)
    launched.wait_for(r"\[launch\] all 3 components alive")
    assert launched.stop(signal.SIGINT) == 0


def _start_ticks(pid: int) -> int:
    """When process ``pid`` started, in clock ticks since boot (Linux /proc)."""
    return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19])
