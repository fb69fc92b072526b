"""``python -m MODULE ARGS...`` in a child forked from this process, when this process has one
thread: the child runs the module on the modules this process has imported, without an
interpreter's start and imports (half a second of CPU for a component's process or a
launcher's).

A study's run is forked from its worker with the modules loaded; it forks its launcher
(``studies.launched``), which forks its fork server (``launch.fork_server``, which forks each
component's process in turn). A process of more threads starts a new interpreter instead
(``single_threaded``): a fork copies the state of a Zenoh runtime or a held lock without the
threads that own them. The child starts as a new interpreter does: Python's default SIGINT and
SIGTERM handlers, fresh standard streams, no logging handler, only its standard descriptors and
``pass_fds`` open, the environment given. ``Forked`` is seen as the ``subprocess.Popen`` of
such a process is (``pid``, ``args``, ``returncode``, ``stdin``, ``stdout``, ``stderr``,
``poll``, ``wait``, ``send_signal``, ``kill``).
"""

from __future__ import annotations

import contextlib
import fcntl
import gc
import logging
import os
import runpy
import select
import signal
import subprocess
import sys
import threading
import traceback
from collections.abc import Mapping
from typing import IO, TypedDict, Unpack


def single_threaded() -> bool:
    """Whether this process has one thread (Linux /proc): a fork copies all of it."""
    return len(os.listdir("/proc/self/task")) == 1


class Forked:
    """A child forked by ``forked``, seen as a ``subprocess.Popen`` in text mode."""

    def __init__(self, pid: int, args: list[str], pipes: dict[str, IO[str] | None]) -> None:
        self.pid, self.args = pid, args
        self.stdin, self.stdout, self.stderr = pipes["stdin"], pipes["stdout"], pipes["stderr"]
        self.returncode: int | None = None
        self._lock = threading.Lock()

    def _reaped(self, flags: int) -> int | None:
        with self._lock:
            if self.returncode is None:
                try:
                    pid, status = os.waitpid(self.pid, flags)
                except ChildProcessError:  # reaped elsewhere: its code is lost, as Popen says
                    pid, status = self.pid, 0
                if pid:
                    self.returncode = os.waitstatus_to_exitcode(status)
            return self.returncode

    def poll(self) -> int | None:
        return self._reaped(os.WNOHANG)

    def wait(self, timeout: float | None = None) -> int:
        """Its exit code, once it ends (``subprocess.TimeoutExpired`` after ``timeout``)."""
        if self.poll() is None and timeout is not None:
            pidfd = os.pidfd_open(self.pid)
            try:
                if not select.select([pidfd], [], [], timeout)[0]:
                    raise subprocess.TimeoutExpired(self.args, timeout)
            finally:
                os.close(pidfd)
        code = self._reaped(0)
        assert code is not None
        return code

    def send_signal(self, signum: int) -> None:
        if self.poll() is None:
            os.kill(self.pid, signum)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)

    def terminate(self) -> None:
        self.send_signal(signal.SIGTERM)


def child_ends(
    stdin: int | None, stdout: IO[str] | int | None, stderr: IO[str] | int | None
) -> tuple[dict[str, IO[str] | None], dict[int, int], list[int]]:
    """The standard streams of a child to be, given as ``subprocess.Popen`` takes them (None:
    this process's; ``PIPE``, ``DEVNULL``, ``STDOUT`` for ``stderr``, a file or a
    descriptor): this process's ends of its pipes (the caller's to close), the child's
    standard descriptors (open here) by where they come from, and the descriptors to close
    here once the child has them."""
    parent_ends: dict[str, IO[str] | None] = {"stdin": None, "stdout": None, "stderr": None}
    child_fds: dict[int, int] = {}  # the child's standard descriptor -> where it comes from
    closed_after: list[int] = []  # this process's copies of what only the child keeps
    for target, (name, given) in enumerate(
        (("stdin", stdin), ("stdout", stdout), ("stderr", stderr))
    ):
        if given is None:
            with contextlib.suppress(OSError):  # not open here: not open there either
                os.fstat(target)
                child_fds[target] = target
        elif given == subprocess.STDOUT:
            if 1 in child_fds:
                child_fds[target] = child_fds[1]
        elif given == subprocess.PIPE:
            read, write = os.pipe()
            mine, theirs = (write, read) if target == 0 else (read, write)
            mode = "w" if target == 0 else "r"
            parent_ends[name] = open(mine, mode, errors="replace")
            child_fds[target] = theirs
            closed_after.append(theirs)
        elif given == subprocess.DEVNULL:
            child_fds[target] = os.open(os.devnull, os.O_RDONLY if target == 0 else os.O_WRONLY)
            closed_after.append(child_fds[target])
        else:
            if not isinstance(given, int):
                given.flush()
            child_fds[target] = given if isinstance(given, int) else given.fileno()
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    return parent_ends, child_fds, closed_after


class ChildOptions(TypedDict, total=False):
    """How a child starts, as ``subprocess.Popen`` takes it: its ``stdin``, ``stdout`` and
    ``stderr`` (``child_ends``), ``env`` (None: this process's), in a session of its own if
    ``start_new_session``, with ``pass_fds`` open (at their numbers)."""

    stdin: int | None
    stdout: IO[str] | int | None
    stderr: IO[str] | int | None
    env: Mapping[str, str] | None
    start_new_session: bool
    pass_fds: tuple[int, ...]


def forked(command: list[str], **how: Unpack[ChildOptions]) -> Forked:
    """``command`` (``[MODULE, ARGS...]``) in a forked child started as ``how`` says."""
    parent_ends, child_fds, closed_after = child_ends(
        how.get("stdin"), how.get("stdout"), how.get("stderr")
    )
    child_fds |= {fd: fd for fd in how.get("pass_fds", ())}
    pid = os.fork()
    if pid == 0:
        run_child(command, child_fds, how.get("env"), how.get("start_new_session", False))
    for descriptor in closed_after:
        os.close(descriptor)
    return Forked(pid, command, parent_ends)


def run_child(
    command: list[str],
    child_fds: dict[int, int],
    env: Mapping[str, str] | None,
    start_new_session: bool,
) -> None:
    """Run ``command`` as a new interpreter would, with ``child_fds`` (its descriptor -> where it
    comes from here) and no other descriptor open, then end with its exit code; never
    returns."""
    code = 1
    try:
        # What this process held as garbage stays uncollected: a finalizer of it would close a
        # descriptor number closed below and maybe reused by then.
        gc.freeze()
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        if start_new_session:
            os.setsid()
        floor = max(child_fds, default=0) + 1  # above every target: none is overwritten
        moved = {target: fcntl.fcntl(fd, fcntl.F_DUPFD, floor) for target, fd in child_fds.items()}
        start = 0
        for target in sorted(moved):
            os.dup2(moved[target], target)
            if start < target:  # closerange(n, n) would close them all
                os.closerange(start, target)
            start = target + 1
        os.closerange(start, os.sysconf("SC_OPEN_MAX"))
        sys.stdin, sys.stdout, sys.stderr = (_stream(0, "r"), _stream(1, "w"), _stream(2, "w"))
        logging.root.handlers.clear()
        logging.root.setLevel(logging.WARNING)
        if env is not None:
            os.environ.clear()
            os.environ.update(env)
        sys.argv = ["-m", *command[1:]]
        sys.modules.pop(command[0], None)  # run afresh as __main__, as ``-m`` runs it
        runpy.run_module(command[0], run_name="__main__", alter_sys=True)
        code = 0
    except SystemExit as end:
        code = end.code if isinstance(end.code, int) else (0 if end.code is None else 1)
    except BaseException:  # said on its output, as an interpreter says it
        traceback.print_exc()
    finally:
        with contextlib.suppress(Exception):
            logging.shutdown()
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)


def _stream(descriptor: int, mode: str) -> IO[str] | None:
    """A fresh standard stream on ``descriptor`` (line-buffered for writing), None when it is
    not open, as a new interpreter has them."""
    try:
        os.fstat(descriptor)
    except OSError:
        return None
    return open(descriptor, mode, buffering=-1 if mode == "r" else 1, closefd=False)
