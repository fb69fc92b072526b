"""A launch run from a study or a test: ``parsimony launch`` as a child process, a client
session to its router, and the waits until its components are alive and reached by the
simulator's clock.

A process with a single thread (a study's run, forked from its worker with the modules loaded)
forks its launcher instead of starting a new interpreter: the child runs ``parsimony.cli`` as
``python -m`` would, on the modules already imported, which saves the interpreter's start and
imports (about half a second of CPU a run). Any other process (more threads: a fork would
copy the state of a Zenoh runtime or a lock without the threads that own it) starts it as a
new interpreter.
"""

from __future__ import annotations

import contextlib
import os
import runpy
import select
import signal
import subprocess
import sys
import time
import traceback
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO

import zenoh

from launch import query
from messages import process
from profiles.profile import Profile

STARTUP_S = 60.0
"""Host seconds the components may take to come up."""
POLL_S = 0.02
"""How often the router, then the components' liveliness and counters, are looked at while
waited for: a look costs about a millisecond of CPU, a wait half a period on average."""


@contextlib.contextmanager
def launched(
    profile_path: Path, log: IO[str] | int = subprocess.DEVNULL, stop_timeout_s: float | None = 30.0
) -> Iterator[subprocess.Popen | Forked]:
    """``parsimony launch PROFILE`` as a child process, its output to ``log``; at the end of
    the block it is stopped by SIGINT (its components in order), killed after
    ``stop_timeout_s`` (None: the launcher's own limits, a recorder's progress, decide)."""
    command = ["parsimony.cli", "launch", str(profile_path)]
    launcher: Launcher
    if len(os.listdir("/proc/self/task")) == 1:
        launcher = forked(command, log)
    else:
        launcher = subprocess.Popen(
            [sys.executable, "-m", *command],
            stdout=log,
            stderr=subprocess.STDOUT,
            env={**os.environ, process.PARENT_PID_ENV: str(os.getpid())},  # it stops if we die
        )
    try:
        yield launcher
    finally:
        process.stop(launcher, signal.SIGINT, stop_timeout_s)


class Forked:
    """A child forked by ``forked``, seen as the ``subprocess.Popen`` of a launcher is."""

    def __init__(self, pid: int, args: list[str]) -> None:
        self.pid, self.args = pid, args
        self.returncode: int | None = None

    def poll(self) -> int | None:
        if self.returncode is None:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        """Its exit code, once it ends (``subprocess.TimeoutExpired`` after ``timeout``)."""
        if self.poll() is None and timeout is not None:
            pidfd = os.pidfd_open(self.pid)
            try:
                if not select.select([pidfd], [], [], timeout)[0]:
                    raise subprocess.TimeoutExpired(self.args, timeout)
            finally:
                os.close(pidfd)
        if self.returncode is None:
            self.returncode = os.waitstatus_to_exitcode(os.waitpid(self.pid, 0)[1])
        return self.returncode

    def send_signal(self, signum: int) -> None:
        if self.poll() is None:
            os.kill(self.pid, signum)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)


def forked(command: list[str], log: IO[str] | int) -> Forked:
    """``python -m MODULE ARGS...`` (``command``) in a child forked from this process, its
    output to ``log``, its standard input and environment this process's; it stops if we die
    (``PARENT_PID_ENV``), and it holds no other file of ours."""
    opened = isinstance(log, int) and log == subprocess.DEVNULL
    if isinstance(log, int):
        target = os.open(os.devnull, os.O_WRONLY) if opened else log
    else:
        log.flush()
        target = log.fileno()
    parent = os.getpid()
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid:
        if opened:
            os.close(target)
        return Forked(pid, command)
    code = 1
    try:  # as a new interpreter starts: the default handlers, fresh streams, only 0, 1, 2 open
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        os.dup2(target, 1)
        os.dup2(target, 2)
        os.closerange(3, os.sysconf("SC_OPEN_MAX"))
        sys.stdout = open(1, "w", closefd=False)  # the child's own, never closed
        sys.stderr = open(2, "w", closefd=False)
        os.environ[process.PARENT_PID_ENV] = str(parent)
        sys.argv = ["-m", *command[1:]]
        sys.modules.pop(command[0], None)  # run afresh as __main__, as ``-m`` runs it
        runpy.run_module(command[0], run_name="__main__", alter_sys=True)
        code = 0
    except SystemExit as end:
        code = end.code if isinstance(end.code, int) else (0 if end.code is None else 1)
    except BaseException:  # noqa: BLE001 - said on its output, as an interpreter would
        traceback.print_exc()
    finally:
        with contextlib.suppress(Exception):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)


Launcher = subprocess.Popen | Forked
"""A launcher as ``launched`` gives it: a new interpreter's, or a forked one."""


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
