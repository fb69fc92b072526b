"""The stop of a profile's children: their order, each one's deadline, and their reaping."""

from __future__ import annotations

import os
import select
import signal
import subprocess
import time
from itertools import groupby
from pathlib import Path

from launch.child import Child, Process
from launch.output import Output
from profiles.profile import ROLES, Profile

CLEAN_STOP_CODES = (0, -signal.SIGTERM)
"""Exit codes that count as a clean stop after SIGTERM."""
QUIET_WAIT_S = 1.0
"""A stopping component slower than this is said to be waited for."""


def cpu_seconds(pid: int) -> float:
    """The user and system CPU time a process has spent (Linux /proc), 0 when it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def wait_ended(process: Process, timeout_s: float) -> int:
    """``process.wait(timeout_s)``, woken by the process's end (a Linux pidfd), not by
    ``wait``'s polls, which grow to 50 ms apart: each stop waited for ends when it does."""
    try:
        pidfd = os.pidfd_open(process.pid)
    except (OSError, AttributeError):  # reaped already, or no pidfd on this system
        return process.wait(timeout_s)
    try:
        ended, _, _ = select.select([pidfd], [], [], timeout_s)
    finally:
        os.close(pidfd)
    if not ended:
        raise subprocess.TimeoutExpired(process.args, timeout_s)
    return process.wait()


def stop_all(children: list[Child], profile: Profile, output: Output) -> None:
    """Stop the running children role by role, tools first and drivers last, and in a role
    each before the components it started ``after``."""
    for child in children:
        if child.restart_at is not None:
            child.failed = True
            output.say(f"{child.spec.name} was waiting to restart; counted as failed")

    def order(child: Child) -> tuple[int, int]:
        return ROLES.index(child.spec.role), profile.start_depth(child.spec)

    running = sorted((c for c in children if c.process is not None), key=order, reverse=True)
    for _, wave in groupby(running, key=order):
        group = list(wave)
        for popen in {id(c.process): c.process for c in group}.values():
            for child in children:
                child.stopping = child.stopping or child.process is popen
            popen.send_signal(signal.SIGTERM)  # none if it has ended (shared, stopped)
        stopped_at = time.monotonic()
        for child in group:
            _reap(child, child.process, stopped_at + child.spec.stop_timeout_s, output)


def _reap(child: Child, process: Process, deadline: float, output: Output) -> None:
    """Wait for a child sent SIGTERM until ``deadline``, then kill it."""
    code = _wait_stopped(child, process, deadline, output)
    if code is None:
        process.kill()
        process.wait()
        output.say(f"{child.spec.name} did not stop in {child.spec.stop_timeout_s:g} s; killed")
        child.failed = True
    else:
        child.failed = child.failed or code not in CLEAN_STOP_CODES
        output.say(f"{child.spec.name} stopped ({code})")
    child.process = None


def _wait_stopped(child: Child, process: Process, deadline: float, output: Output) -> int | None:
    """Its exit code, or None once ``deadline`` passed; a recorder's deadline moves on
    while it spends CPU time. A wait longer than ``QUIET_WAIT_S`` is said."""
    spent, said = cpu_seconds(process.pid), False
    while True:
        left = max(0.0, deadline - time.monotonic())
        try:
            return wait_ended(process, left if said else min(left, QUIET_WAIT_S))
        except subprocess.TimeoutExpired:
            pass
        if not said:
            said = True
            if time.monotonic() < deadline:
                progress = " without progress" if child.spec.role == "recorder" else ""
                output.say(
                    f"waiting for {child.spec.name} to stop (killed after "
                    f"{child.spec.stop_timeout_s:g} s{progress})"
                )
                continue
        now_spent = cpu_seconds(process.pid)
        if child.spec.role != "recorder" or now_spent <= spent:
            return None
        spent, deadline = now_spent, time.monotonic() + child.spec.stop_timeout_s
