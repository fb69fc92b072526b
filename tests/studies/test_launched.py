"""A launch from a study's run (studies/launched.py): a process with one thread forks its
launcher, which runs, answers and stops as the one a new interpreter runs; a forked child
keeps a Popen's poll, wait and signals."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from profiles.endpoints import free_port
from studies.launched import forked

ONE_THREAD = """
import json, os, sys
from pathlib import Path
from launch.query import live_components
from profiles.profile import load_profile
from studies.launched import connect, launched

profile, out = Path(sys.argv[1]), Path(sys.argv[2])
threads = len(os.listdir("/proc/self/task"))
with (out / "launch.log").open("w") as log, launched(profile, log) as launcher:
    with connect(load_profile(profile), launcher) as session:
        while "pub" not in live_components(session, "forked", 0.5):
            assert launcher.poll() is None
    kind = type(launcher).__name__
code = launcher.returncode
print(json.dumps({"threads": threads, "launcher": kind, "code": code, "pid": launcher.pid}))
"""
"""A run's launch in a process of one thread (OpenBLAS held to one): its launcher, started,
answering and stopped."""


def test_a_process_of_one_thread_forks_a_launcher_that_runs_and_stops(tmp_path: Path) -> None:
    profile = tmp_path / "system.yaml"
    component = {"name": "pub", "module": "scripted_publisher", "role": "tool"}
    router = {"router": [f"tcp/127.0.0.1:{free_port()}"]}
    system = {"namespace": "forked", "zenoh": router, "components": [component]}
    profile.write_text(yaml.safe_dump(system))
    done = subprocess.run(
        [sys.executable, "-c", ONE_THREAD, str(profile), str(tmp_path)],
        capture_output=True,
        text=True,
        env={**os.environ, "OPENBLAS_NUM_THREADS": "1"},
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    found = json.loads(done.stdout)
    assert found | {"pid": 0} == {"threads": 1, "launcher": "Forked", "code": 0, "pid": 0}
    log = (tmp_path / "launch.log").read_text()
    assert "[launch] router listening" in log
    assert "pub alive" in log and "pub stopped (0)" in log


def test_a_forked_child_runs_its_module_and_answers_as_a_popen(tmp_path: Path) -> None:
    with (tmp_path / "out.log").open("w") as log:
        child = forked(["platform"], log)
        assert child.wait(60) == 0 and child.poll() == 0
    assert (tmp_path / "out.log").read_text().startswith("Linux")
    with (tmp_path / "error.log").open("w") as log:
        assert forked(["no_such_module_here"], log).wait(60) == 1
    assert "No module named no_such_module_here" in (tmp_path / "error.log").read_text()


def test_a_forked_child_waited_for_too_briefly_is_stopped_by_a_signal() -> None:
    child = forked(["timeit", "-n1", "-r1", "import time; time.sleep(60)"], subprocess.DEVNULL)
    with pytest.raises(subprocess.TimeoutExpired):
        child.wait(0.05)
    assert child.poll() is None
    child.send_signal(signal.SIGINT)  # Python's KeyboardInterrupt, as in a new interpreter
    assert child.wait(60) != 0
    child.kill()  # gone already: nothing to do
