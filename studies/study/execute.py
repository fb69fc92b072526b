"""One run in a child process of its own, on whichever machine executes it: forked from the
worker (its modules already imported, so a fork costs tens of milliseconds, not an
interpreter's start), killed past the run's time limit with every process it started (its
process group), and its crash (a signal, an exit) or its error told apart from its figures. A
simulated run's namespace is named after that child's process id: two runs never share one."""

from __future__ import annotations

import contextlib
import os
import pickle
import select
import signal
import sys
import time
import traceback
from typing import Any

from studies.study import runs
from studies.study.sweep import Run

OK, FAILED = "ok", "failed"
RUNNING: set[int] = set()
"""The process groups of the runs under way in this process (``stop_all``)."""


def execute(run: Run) -> dict[str, Any]:
    """``run``'s outcome: ``status`` (OK or FAILED), ``reason`` (empty when OK), ``wall_s`` and,
    when OK, ``figures`` (``runs.perform``). It never raises for the run's fault."""
    started = time.monotonic()
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: its output to /dev/null (or the run's log), its answer to the pipe
        os.close(read)
        _child(run, write)
    with contextlib.suppress(OSError):  # its own process group, with all it starts
        os.setpgid(pid, pid)
    RUNNING.add(pid)
    os.close(write)
    payload, timed_out = _read(read, started + run.time_limit_s)
    os.close(read)
    if timed_out:
        _kill(pid)
    _, status = os.waitpid(pid, 0)
    RUNNING.discard(pid)
    wall_s = round(time.monotonic() - started, 3)
    if timed_out:
        return failed(f"hung: no answer within its time limit of {run.time_limit_s:g} s", wall_s)
    if not payload:
        how = (
            f"killed by signal {signal.Signals(os.WTERMSIG(status)).name}"
            if os.WIFSIGNALED(status)
            else f"exit code {os.waitstatus_to_exitcode(status)}"
        )
        return failed(f"crashed: its process ended ({how}) without an answer", wall_s)
    kind, value = pickle.loads(payload)
    if kind == "error":
        return failed(value, wall_s)
    return {"status": OK, "reason": "", "wall_s": wall_s, "figures": value}


def stop_all() -> None:
    """Kill the runs under way and every process they started (a study stopped)."""
    for pid in list(RUNNING):
        _kill(pid)


def _kill(pid: int) -> None:
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(pid, signal.SIGKILL)


def failed(reason: str, wall_s: float) -> dict[str, Any]:
    return {"status": FAILED, "reason": reason, "wall_s": wall_s, "figures": None}


def _read(fd: int, deadline: float) -> tuple[bytes, bool]:
    """All ``fd`` holds until its writer closes it, or what came by ``deadline`` (True: late)."""
    chunks = []
    while True:
        left = deadline - time.monotonic()
        if left <= 0 or not select.select([fd], [], [], left)[0]:
            return b"", True
        chunk = os.read(fd, 1 << 20)
        if not chunk:
            return b"".join(chunks), False
        chunks.append(chunk)


def _child(run: Run, write: int) -> None:
    """Run ``run`` and write its answer to ``write``; never returns."""
    code = 0
    try:
        os.setpgid(0, 0)
        for stop in (signal.SIGINT, signal.SIGTERM):  # the study's handlers are not the run's
            signal.signal(stop, signal.SIG_DFL)
        log = os.path.join(run.out, "run.log") if run.out else os.devnull
        if run.out:
            os.makedirs(run.out, exist_ok=True)
        target = os.open(log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(target, 1)
        os.dup2(target, 2)
        sys.stdout = open(1, "w", closefd=False)  # fresh objects: no lock of the parent's
        sys.stderr = open(2, "w", closefd=False)
        try:
            answer = ("ok", runs.perform(run))
        except Exception as error:  # the run's own fault, said in one line, the trace in the log
            traceback.print_exc()
            answer = ("error", f"{type(error).__name__}: {error}".splitlines()[0])
        with os.fdopen(write, "wb") as pipe:
            pipe.write(pickle.dumps(answer))
        sys.stdout.flush()
        sys.stderr.flush()
    except BaseException:
        code = 1
    os._exit(code)
