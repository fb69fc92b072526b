"""`parsimony record`, `rerun` and `record --recover` as a user runs them: the recorder stops
with the command however the command ends, a missing router is said at once, and no input or
existing file is written over."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import zenoh

from launch.query import live_components, statuses
from messages.process import EXIT_FOR_GOOD
from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from record.session_reader import info
from record.sessions import load_session
from studies.launched import connect, launched
from tests.launch.conftest import profile_file
from tests.parsimony.in_process import completed
from tests.processes import process_gone


def system_profile(directory: Path) -> Path:
    """A profile of one scripted publisher at 100 Hz, namespace ``rec``."""
    publisher = {"name": "pub", "module": "scripted_publisher", "role": "tool"}
    return profile_file(directory, [{**publisher, "params": {"rate_hz": 100.0}}], namespace="rec")


@dataclass
class System:
    """A launched system of one publisher (100 Hz), which each test's `parsimony record`
    records while it runs."""

    profile: Path
    launcher: subprocess.Popen
    session: zenoh.Session


@pytest.fixture(scope="module")
def system(tmp_path_factory: pytest.TempPathFactory) -> Iterator[System]:
    profile = system_profile(tmp_path_factory.mktemp("system"))
    with launched(profile) as launcher, connect(load_profile(profile), launcher) as session:
        while "pub" not in live_components(session, "rec", 0.5):
            assert launcher.poll() is None
        yield System(profile, launcher, session)


@pytest.mark.parametrize("how", [signal.SIGKILL, signal.SIGTERM, signal.SIGINT])
def test_the_recorder_stops_with_the_record_command(
    system: System, tmp_path: Path, how: signal.Signals
) -> None:
    """However `parsimony record` ends (kill -9 too), its recorder stops and nothing is left
    in the temporary directory; on SIGINT or SIGTERM the command passes the signal on and the
    file gets its footer."""
    out = tmp_path / "k.mcap"
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    command = subprocess.Popen(
        [sys.executable, "-m", "parsimony.cli", "record", str(system.profile), "-o", str(out)],
        env={**os.environ, "TMPDIR": str(temporary)},
    )
    while not out.exists() or info(out)["messages"] < 50:
        assert command.poll() is None
        time.sleep(0.1)  # recording: at least a chunk flushed
    child = statuses(system.session, "rec")["recorder"].pid
    command.send_signal(how)
    command.wait()
    while not process_gone(child):
        time.sleep(0.1)  # the recorder goes too (the test fails by hanging if not)
    assert system.launcher.poll() is None  # the recorded system runs on
    assert list(temporary.iterdir()) == []
    if how != signal.SIGKILL:
        assert command.returncode == 0
        assert info(out)["complete"], "the recorder wrote its footer"
    assert load_session(out)["robot/state"]


def test_record_without_a_router_says_so_and_exits_2(tmp_path: Path) -> None:
    done = completed("record", str(system_profile(tmp_path)), "-o", str(tmp_path / "k.mcap"))
    assert done.returncode == 2 and "cannot reach a router" in done.stderr, done.stderr
    assert not (tmp_path / "k.mcap").exists()


def test_no_command_writes_over_its_input_or_an_existing_file(
    system: System, tmp_path: Path
) -> None:
    profile = system.profile
    recording = tmp_path / "k.mcap"
    command = subprocess.Popen(
        [sys.executable, "-m", "parsimony.cli", "record", str(profile), "-o", str(recording)]
    )
    while not recording.exists() or info(recording)["messages"] < 50:
        assert command.poll() is None
        time.sleep(0.1)
    command.send_signal(signal.SIGINT)
    assert command.wait() == 0
    kept = recording.read_bytes()
    for arguments in (
        ["rerun", str(recording), "--controller", "lp", "-o", str(recording)],
        ["record", "--recover", str(recording), "-o", str(recording)],
        ["record", str(profile), "-o", str(recording)],
    ):
        done = completed(*arguments)
        assert done.returncode == 2, (arguments, done.stderr)
        assert "Traceback" not in done.stderr and str(recording) in done.stderr, done.stderr
        assert recording.read_bytes() == kept
    other = tmp_path / "other.mcap"
    other.write_bytes(b"mine")
    done = completed("record", "--recover", str(recording), "-o", str(other))
    assert done.returncode == 2 and "give --force" in done.stderr
    assert other.read_bytes() == b"mine"
    done = completed("record", "--recover", str(recording), "-o", str(other), "--force")
    assert done.returncode == 0, done.stderr
    assert info(other)["messages"] == info(recording)["messages"]


def test_a_robot_file_that_is_no_description_is_one_line_from_report_and_rerun(
    tmp_path: Path,
) -> None:
    """A robot file of YAML that is not a mapping is said as such (before: 'missing or invalid
    field: list indices must be integers or slices, not str')."""
    robot = tmp_path / "robot.yaml"
    robot.write_text("- arm\n- base\n")
    done = completed(
        "report", str(tmp_path / "k.mcap"), "--out", str(tmp_path / "report"), "--robot", str(robot)
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr == (
        f"report: {robot}: a robot description is a mapping (arm:, base:, "
        "...), this file holds a list\n"
    )
    recording = tmp_path / "k.mcap"
    recording.write_bytes(b"")
    done = completed(
        "rerun",
        str(recording),
        "--controller",
        "lp",
        "-o",
        str(tmp_path / "rerun.mcap"),
        "--robot",
        str(robot),
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr == (
        f"rerun: {robot}: a robot description is a mapping (arm:, base:, "
        "...), this file holds a list\n"
    )


def test_record_onto_a_full_disk_says_so_in_one_line_and_its_file_recovers(
    system: System, tmp_path: Path
) -> None:
    """`parsimony record` onto a real tmpfs, mounted by the test in a mount namespace of its own
    (``unshare``), which another file fills up once the recording holds a flushed chunk: the
    recorder stops for good when the disk is full, the command exits non-zero with one line
    saying so, no traceback, and the file recovers with what was flushed. (Before, the disk was
    64 KiB from the start, and a first flush late on a loaded machine did not fit in it.)"""
    unshare = shutil.which("unshare")
    probe = unshare and subprocess.run(
        [unshare, "-rm", "mount", "-t", "tmpfs", "tmpfs", str(tmp_path)], capture_output=True
    )
    if not probe or probe.returncode != 0:
        pytest.skip("no mount namespace here to mount a tmpfs in")
    profile = system.profile
    disk = tmp_path / "disk"
    disk.mkdir()
    recording, recovered = disk / "k.mcap", tmp_path / "recovered.mcap"
    python = f"{sys.executable} -m"
    flushed = (  # exits 0 once the recording holds a flushed chunk of at least 50 messages
        f"{sys.executable} -c 'import sys; from record.session_reader import info; "
        f'sys.exit(info(sys.argv[1])["messages"] < 50)\' {recording}'
    )
    script = (
        f"mount -t tmpfs -o size=1m tmpfs {disk} || exit 99; "
        f"{python} parsimony.cli record {profile} -o {recording} & "
        f"until [ -s {recording} ] && {flushed} 2>/dev/null; do sleep 0.1; done; "
        f"cat /dev/zero > {disk}/filler 2>/dev/null; wait $!; "
        f"code=$?; {python} parsimony.cli record --recover {recording} "
        f"-o {recovered} >&2; exit $code"
    )
    done = subprocess.run(
        [unshare, "-rm", "sh", "-c", script],
        capture_output=True,
        text=True,
        cwd=DEPLOY.parent,  # the project's root: the flushed check imports the project
        timeout=600,  # a safety net: a recorder that never flushes fails the test, not the suite
    )
    assert done.returncode == EXIT_FOR_GOOD, done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    full = [line for line in done.stderr.splitlines() if "No space left on device" in line]
    assert len(full) == 1 and f"cannot write {recording}" in full[0], done.stderr
    states = load_session(recovered)["robot/state"]
    seqs = [s.header.seq for s in states]  # what was flushed before the disk filled, none lost
    assert len(seqs) > 10
    # ... by the recorder: a publisher that the launcher's watchdog restarted on a loaded
    # machine counts again from 0.
    starts = [0, *(i for i in range(1, len(seqs)) if seqs[i] < seqs[i - 1]), len(seqs)]
    for run in (seqs[a:b] for a, b in zip(starts, starts[1:], strict=False)):
        assert run == list(range(run[0], run[0] + len(run))), run
