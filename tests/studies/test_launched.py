"""A launch from a study's run (studies/launched.py): a process with one thread forks its
launcher, which forks its fork server, which forks its children; all run, answer and stop as a
new interpreter's do."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import yaml

from profiles.endpoints import free_port
from record.session_reader import info

ONE_THREAD = """
import json, os, sys
from pathlib import Path
from launch.query import live_components, statuses
from profiles.profile import load_profile
from studies.launched import connect, launched

profile, out = Path(sys.argv[1]), Path(sys.argv[2])
threads = len(os.listdir("/proc/self/task"))
with (out / "launch.log").open("w") as log, launched(profile, log) as launcher:
    with connect(load_profile(profile), launcher) as session:
        while {"pub", "echo", "rec"} - set(live_components(session, "forked", 0.5)):
            assert launcher.poll() is None
        while not getattr(statuses(session, "forked").get("rec"), "counters", {}).get("written"):
            assert launcher.poll() is None
        def children(pid):
            return open(f"/proc/{pid}/task/{pid}/children").read().split()
        served = [pid for server in children(launcher.pid) for pid in children(server)]
        commands = [Path(f"/proc/{pid}/cmdline").read_bytes() for pid in served]
    kind = type(launcher).__name__
forked = [b"-m\\x00components." not in command for command in commands]
code = launcher.returncode
print(json.dumps({"threads": threads, "launcher": kind, "code": code, "forked": forked}))
"""
"""A run's launch in a process of one thread (OpenBLAS held to one): its launcher, started,
answering and stopped."""


def test_a_process_of_one_thread_forks_a_launcher_whose_fork_server_forks_its_children(
    tmp_path: Path,
) -> None:
    """The launcher forked, and the shared process and the recorder's forked from its fork
    server, itself forked: they run, answer, record and stop as a new interpreter's do."""
    profile, recording = tmp_path / "system.yaml", tmp_path / "session.mcap"
    components = [
        {"name": name, "module": "scripted_publisher", "role": "tool"} for name in ("pub", "echo")
    ]
    recorder = {"name": "rec", "module": "recorder", "role": "recorder"}
    components.append(recorder | {"params": {"path": str(recording)}})
    router = {"router": [f"tcp/127.0.0.1:{free_port()}"]}
    system = {"namespace": "forked", "zenoh": router, "processes": "shared"}
    profile.write_text(yaml.safe_dump(system | {"components": components}))
    done = subprocess.run(
        [sys.executable, "-c", ONE_THREAD, str(profile), str(tmp_path)],
        capture_output=True,
        text=True,
        env={**os.environ, "OPENBLAS_NUM_THREADS": "1"},
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    found = json.loads(done.stdout)
    assert found == {"threads": 1, "launcher": "Forked", "code": 0, "forked": [True, True]}
    log = (tmp_path / "launch.log").read_text()
    assert "[launch] router listening" in log and "pub, echo in one process" in log
    assert "INFO pub running" in log and "INFO echo running" in log  # their own log lines
    assert "pub stopped (0)" in log and "echo stopped (0)" in log and "rec stopped (0)" in log
    recorded = info(recording)
    assert recorded["complete"] and recorded["messages"] > 0
