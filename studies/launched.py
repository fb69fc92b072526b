"""A launch run from a study or a test: ``parsimony launch`` as a child process, a client
session to its router, and the waits until its components are alive and reached by the
simulator's clock.

A process with a single thread (a study's run, forked from its worker with the modules loaded)
forks its launcher instead of starting a new interpreter (``launch.forked``); any other starts
``python -m parsimony.cli launch`` as a new interpreter.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO

import zenoh

from launch import query
from launch.forked import Forked, forked, single_threaded
from messages import process
from profiles.profile import Profile

STARTUP_S = 60.0
"""Host seconds the components may take to come up."""
POLL_S = 0.02
"""How often the router, then the components' liveliness and counters, are looked at while
waited for: a look costs about a millisecond of CPU, a wait half a period on average."""


Launcher = subprocess.Popen | Forked
"""A launcher as ``launched`` gives it: a new interpreter's, or a forked one."""


@contextlib.contextmanager
def launched(
    profile_path: Path, log: IO[str] | int = subprocess.DEVNULL, stop_timeout_s: float | None = 30.0
) -> Iterator[Launcher]:
    """``parsimony launch PROFILE`` as a child process, its output to ``log``; at the end of
    the block it is stopped by SIGINT (its components in order), killed after
    ``stop_timeout_s`` (None: the launcher's own limits, a recorder's progress, decide)."""
    command = ["parsimony.cli", "launch", str(profile_path)]
    env = {**os.environ, process.PARENT_PID_ENV: str(os.getpid())}  # it stops if we die
    launcher: Launcher
    if single_threaded():  # a study's run: forked from its worker, the modules loaded
        launcher = forked(command, stdout=log, stderr=subprocess.STDOUT, env=env)
    else:
        launcher = subprocess.Popen(
            [sys.executable, "-m", *command], stdout=log, stderr=subprocess.STDOUT, env=env
        )
    try:
        yield launcher
    finally:
        process.stop(launcher, signal.SIGINT, stop_timeout_s)


def connect(profile: Profile, launcher: Launcher) -> zenoh.Session:
    """A client session to the launch's router, once the router listens."""
    deadline = time.monotonic() + STARTUP_S
    while True:
        try:
            return query.Target(profile.namespace, profile.zenoh).open()
        except query.QueryError:
            if launcher.poll() is None and time.monotonic() > deadline:
                raise
        running(launcher)  # it refused the profile, or failed at once
        time.sleep(POLL_S)  # the launcher opens its router first thing


def wait_alive(session: zenoh.Session, profile: Profile, launcher: Launcher) -> None:
    """Wait until every enabled component of the profile is alive."""
    wanted = {spec.name for spec in profile.components if spec.enabled}

    def missing() -> list[str]:
        return sorted(wanted - set(query.live_components(session, profile.namespace, 0.5)))

    wait_launch(launcher, missing, "did not come up")


def wait_reached(session: zenoh.Session, profile: Profile, launcher: Launcher) -> None:
    """Wait until every component that reads ``sim/clock`` has received the paused simulator's
    clock: a component's liveliness does not prove that the simulator's data reaches it yet,
    and one reached late would miss the first steps (the recorder, the first camera frame)."""

    def missing() -> list[str]:
        found = query.statuses(session, profile.namespace, 0.5)
        return [
            name
            for name, status in found.items()
            if status.counters.get("received.sim/clock", 1) == 0
        ]

    wait_launch(launcher, missing, "never received the simulator's clock")


def wait_launch(launcher: Launcher, missing: Callable[[], list[str]], what: str) -> None:
    """Poll ``missing()``, the components still waited for, until it is empty; fail, naming
    them, when the launch stops or after ``STARTUP_S``."""
    deadline = time.monotonic() + STARTUP_S
    while waiting := missing():
        running(launcher)
        if time.monotonic() > deadline:
            raise RuntimeError(f"{', '.join(waiting)} {what} in {STARTUP_S:.0f} s")
        time.sleep(POLL_S)  # polling the router (liveliness tokens, the components' counters)


def running(launcher: Launcher) -> None:
    """RuntimeError, with its exit code, when the launch has stopped."""
    if launcher.poll() is not None:
        raise RuntimeError(f"the launch stopped (exit {launcher.returncode}); see its log")
