"""A fork server: one process of one thread that loads a launch's component modules once and
forks each ``python -m MODULE ARGS`` process the launcher asks for on them (``launch.forked``),
as Python's multiprocessing "forkserver" does: a component's process starts without an
interpreter's start and imports (half a second of CPU each).

The launcher starts it (``ForkServer``) before its router opens: forked when the launcher has
one thread (a study's run), else ``python -m launch.fork_server FD MODULES...``, a new
interpreter held to one thread (OpenBLAS's). It serves requests on a unix socket pair: the
command, its environment, its session, and its descriptors, which keep their numbers in the
child; it answers each with the child's pid and pidfd, and reports its exit code when it ends.
It is the parent of its children, which their ``PARENT_PID_ENV`` names; it runs in a session of
its own (a terminal's Ctrl-C reaches the launcher alone, which stops them in order) and ends
when the launcher does, its children then stopping by themselves.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import os
import select
import signal
import socket
import subprocess
import sys
import threading
from collections import deque
from collections.abc import Callable
from typing import IO, Unpack

from launch.forked import ChildOptions, Forked, child_ends, forked, run_child, single_threaded
from messages.process import PARENT_PID_ENV

MODULE = "launch.fork_server"
MESSAGE_BYTES = 1 << 20
"""The largest request (its environment the most of it)."""
LOST = 1
"""The exit code of a child whose server ended before it: its own is lost."""
CLOSE_S = 10.0
"""How long the server may take to end once the launcher closes it; then it is killed."""
ANSWER_S = 60.0
"""How long a request may wait for the server's answer, its modules loading first (a second or
two); then the server is taken for hung, a module that never loads: it is killed, and this
child and the next start as new interpreters."""


def warn(text: str) -> None:
    """``text`` on the error stream, a line."""
    print(text, file=sys.stderr, flush=True)


class Served:
    """A process forked by the server, seen as a ``subprocess.Popen`` in text mode."""

    def __init__(self, args: list[str], pipes: dict[str, IO[str] | None]) -> None:
        self.pid, self.args, self.returncode = 0, args, None
        self.stdin, self.stdout, self.stderr = pipes["stdin"], pipes["stdout"], pipes["stderr"]
        self._pidfd = -1
        self._lock = threading.Lock()
        self._answered, self._ended = threading.Event(), threading.Event()

    def _end(self, code: int) -> None:
        with self._lock:
            self.returncode = code
            os.close(self._pidfd)
        self._ended.set()

    def poll(self) -> int | None:
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        """Its exit code, once it ends (``subprocess.TimeoutExpired`` after ``timeout``)."""
        if not self._ended.wait(timeout):
            raise subprocess.TimeoutExpired(self.args, timeout or 0.0)
        assert self.returncode is not None
        return self.returncode

    def send_signal(self, signum: int) -> None:
        with self._lock, contextlib.suppress(ProcessLookupError):
            if self.returncode is None:  # its pidfd: never another process of the same pid
                signal.pidfd_send_signal(self._pidfd, signum)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)

    def terminate(self) -> None:
        self.send_signal(signal.SIGTERM)


class ForkServer:
    """The launcher's side of a fork server loading ``modules``: its process and its replies,
    read by one thread."""

    def __init__(
        self, modules: list[str], say: Callable[[str], None] = warn, answer_s: float = ANSWER_S
    ) -> None:
        self._say, self.answer_s = say, answer_s
        self._channel, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        command = [MODULE, str(theirs.fileno()), *modules]
        how: ChildOptions = {
            "stdin": subprocess.DEVNULL,
            "env": {**os.environ, "OPENBLAS_NUM_THREADS": "1"},  # one thread, as it forks
            "start_new_session": True,
            "pass_fds": (theirs.fileno(),),
        }
        if single_threaded():
            self.process: subprocess.Popen[bytes] | Forked = forked(command, **how)
        else:
            self.process = subprocess.Popen([sys.executable, "-m", *command], **how)
        theirs.close()
        self._lock = threading.Lock()
        self._asked: deque[Served] = deque()
        self._running: dict[int, Served] = {}
        self._gone = False
        threading.Thread(target=self._read, daemon=True).start()

    def spawn(self, command: list[str], **how: Unpack[ChildOptions]) -> Served | None:
        """``command`` (``[MODULE, ARGS...]``) forked by the server, started as ``forked``
        starts it; None when the server is gone, refuses (it has more than one thread) or does
        not answer in ``answer_s`` (then killed), the caller then starting a new interpreter."""
        parent_ends, child_fds, closed_after = child_ends(
            how.get("stdin"), how.get("stdout"), how.get("stderr")
        )
        child_fds |= {fd: fd for fd in how.get("pass_fds", ())}
        env = how.get("env")
        request = {
            "command": command,
            "env": dict(os.environ if env is None else env),
            "session": how.get("start_new_session", False),
            "fds": list(child_fds),
        }
        served = Served(command, parent_ends)
        with self._lock:  # asked in the order of the replies, or answered as the server goes
            if self._gone:
                served._answered.set()
            else:
                self._asked.append(served)
                try:
                    socket.send_fds(
                        self._channel, [json.dumps(request).encode()], list(child_fds.values())
                    )
                except OSError:  # gone, its end not read yet
                    self._asked.remove(served)
                    served._answered.set()
        if not served._answered.wait(self.answer_s):
            waited = f"the fork server did not answer in {self.answer_s:g} s"
            self._say(f"{waited}: killed, components start as new interpreters")
            self.process.kill()  # its end answers every request (``_read``)
            served._answered.wait()
        for descriptor in closed_after:
            os.close(descriptor)
        if served.pid:
            return served
        for pipe in parent_ends.values():
            if pipe is not None:
                pipe.close()
        return None

    def _read(self) -> None:
        """The server's replies: a child's pid and pidfd, or its exit code. Once the server is
        gone, the children it left are seen ended when their processes are."""
        while True:
            try:
                message, fds, _, _ = socket.recv_fds(self._channel, 4096, 1)
            except OSError:
                message = b""
            if not message:
                break
            reply = json.loads(message)
            if "code" in reply:
                self._running.pop(reply["pid"])._end(reply["code"])
                continue
            with self._lock:
                served = self._asked.popleft()
            if fds:
                served.pid, served._pidfd = reply["pid"], fds[0]
                self._running[served.pid] = served
            served._answered.set()
        with self._lock:
            self._gone = True
            for served in self._asked:
                served._answered.set()
            self._asked.clear()
        while self._running:
            for pidfd in select.select([s._pidfd for s in self._running.values()], [], [])[0]:
                pid = next(pid for pid, s in self._running.items() if s._pidfd == pidfd)
                self._running.pop(pid)._end(LOST)

    def close(self) -> None:
        """End the server (its children are stopped, or stop by themselves) and reap it."""
        with contextlib.suppress(OSError):
            self._channel.shutdown(socket.SHUT_RDWR)
        try:
            self.process.wait(CLOSE_S)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def serve(channel: socket.socket) -> None:
    """Fork a child for each request on ``channel``, answer its pid and pidfd, and report its
    exit code; return when the launcher is gone."""
    children: dict[int, int] = {}  # pidfd -> pid
    while True:
        for ready in select.select([channel, *children], [], [])[0]:
            if ready is not channel:
                pid, status = os.waitpid(children.pop(ready), 0)
                os.close(ready)
                code = os.waitstatus_to_exitcode(status)
                channel.send(json.dumps({"pid": pid, "code": code}).encode())
                continue
            message, fds, _, _ = socket.recv_fds(channel, MESSAGE_BYTES, 256)
            if not message:
                return
            request = json.loads(message)
            if not single_threaded():  # a fork would copy another thread's state without it
                channel.send(json.dumps({"refused": "not one thread"}).encode())
            else:
                env = request["env"]
                if PARENT_PID_ENV in env:
                    env[PARENT_PID_ENV] = str(os.getpid())  # its parent is this process
                child_fds = dict(zip(request["fds"], fds, strict=True))
                pid = os.fork()
                if pid == 0:
                    run_child(request["command"], child_fds, env, request["session"])
                pidfd = os.pidfd_open(pid)
                children[pidfd] = pid
                socket.send_fds(channel, [json.dumps({"pid": pid}).encode()], [pidfd])
            for descriptor in fds:
                os.close(descriptor)


def main(argv: list[str]) -> None:
    """``python -m launch.fork_server FD MODULES...``: load the modules, then serve on FD."""
    channel = socket.socket(fileno=int(argv[0]))
    for module in argv[1:]:
        with contextlib.suppress(Exception):  # its child says why, as a new interpreter would
            importlib.import_module(module)
    with contextlib.suppress(BrokenPipeError, ConnectionResetError):
        serve(channel)


if __name__ == "__main__":
    main(sys.argv[1:])
