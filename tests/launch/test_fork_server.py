"""The fork server (launch/fork_server.py): a served child runs as a new interpreter's would (its
module and arguments, environment, session, pipes and descriptors by number), is the server's
child, and answers as a Popen; once the server is gone, its children are seen ending and new
ones are refused."""

from __future__ import annotations

import json
import os
import signal
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from launch.fork_server import LOST, ForkServer
from messages.process import PARENT_PID_ENV
from tests.launch.conftest import DEADLINE_S

SAYS = (
    "import json, os; print(json.dumps({'ppid': os.getppid(), 'parent': os.environ['%s'], "
    "'x': os.environ.get('X'), 'own_session': os.getsid(0) == os.getpid(), "
    "'read': open('/proc/self/fd/%d').read()}))"
)
"""What a served child says of itself: ``timeit -n1 -r1`` runs it once."""


def timeit(statement: str) -> list[str]:
    """``python -m timeit`` running ``statement`` once."""
    return ["timeit", "-n1", "-r1", statement]


@pytest.fixture(scope="module")
def server() -> Iterator[ForkServer]:
    """One fork server, a new interpreter (this process has more than one thread)."""
    served = ForkServer(["json"])
    yield served
    served.close()


def test_a_served_child_runs_its_module_as_the_servers_child_with_its_descriptors(
    server: ForkServer, tmp_path: Path
) -> None:
    """Its arguments, environment, session, output pipe and a passed descriptor at its own
    number (as ``parsimony launch --record`` passes its profile); its parent is the server,
    which its ``PARENT_PID_ENV`` names."""
    (tmp_path / "profile.yaml").write_text("namespace: test\n")
    given = os.open(tmp_path / "profile.yaml", os.O_RDONLY)
    number = os.dup2(given, 97 if given != 97 else 98, inheritable=False)
    os.close(given)
    env = {**os.environ, "X": "y", PARENT_PID_ENV: str(os.getpid())}
    child = server.spawn(
        timeit(SAYS % (PARENT_PID_ENV, number)),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        env=env,
        start_new_session=True,
        pass_fds=(number,),
    )
    os.close(number)
    assert child is not None and child.stdout is not None
    lines = child.stdout.read().splitlines()
    assert child.wait(DEADLINE_S) == 0 and child.poll() == 0
    said = json.loads(lines[0])
    server_pid = server.process.pid
    assert said == {
        "ppid": server_pid,
        "parent": str(server_pid),
        "x": "y",
        "own_session": True,
        "read": "namespace: test\n",
    }
    assert lines[1].startswith("1 loop, best of 1")  # timeit's arguments, as given


def test_a_served_childs_exit_code_is_reported_and_a_wait_may_time_out(
    server: ForkServer,
) -> None:
    failing = server.spawn(timeit("import os; os._exit(3)"), stdout=subprocess.DEVNULL)
    assert failing is not None and failing.wait(DEADLINE_S) == 3
    sleeping = server.spawn(timeit("import time; time.sleep(60)"), stdout=subprocess.DEVNULL)
    assert sleeping is not None
    with pytest.raises(subprocess.TimeoutExpired):
        sleeping.wait(0.05)
    assert sleeping.poll() is None
    sleeping.kill()
    assert sleeping.wait(DEADLINE_S) == -signal.SIGKILL
    sleeping.send_signal(signal.SIGTERM)  # ended: nothing to do


def test_once_the_server_is_gone_its_children_are_seen_ending_and_new_ones_are_refused() -> None:
    """Never a wait that hangs: a child whose end the server could not report is seen ended
    when its process is; the launcher then starts a new interpreter (``spawn`` says None)."""
    server = ForkServer([])
    child = server.spawn(timeit("import time; time.sleep(60)"), stdout=subprocess.DEVNULL)
    assert child is not None
    server.process.kill()
    server.process.wait()
    assert server.spawn(["platform"], stdout=subprocess.DEVNULL) is None
    os.kill(child.pid, signal.SIGKILL)
    assert child.wait(DEADLINE_S) == LOST
    server.close()


def test_a_server_of_more_than_one_thread_refuses_to_fork(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A module it loaded started a thread: a fork would copy that thread's state without it,
    so the server refuses and the caller starts a new interpreter (``spawn`` says None)."""
    (tmp_path / "starts_a_thread.py").write_text(
        "import threading, time\n"
        "threading.Thread(target=time.sleep, args=(60,), daemon=True).start()\n"
    )
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    server = ForkServer(["starts_a_thread"])
    try:
        assert server.spawn(["platform"], stdout=subprocess.DEVNULL) is None
    finally:
        server.close()


def test_a_server_that_never_answers_is_killed_and_its_caller_starts_a_new_interpreter(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A module that never finishes loading: the request waits ``answer_s``, not for ever; the
    server is killed, which the launch is told, and ``spawn`` says None, now and for the next
    child."""
    (tmp_path / "never_loads.py").write_text("import threading\nthreading.Event().wait()\n")
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    said: list[str] = []
    server = ForkServer(["never_loads"], said.append, answer_s=0.5)
    try:
        assert server.spawn(["platform"], stdout=subprocess.DEVNULL) is None
        assert "did not answer in 0.5 s" in said[0], said
        assert server.process.wait(DEADLINE_S) == -signal.SIGKILL
        assert server.spawn(["platform"], stdout=subprocess.DEVNULL) is None
    finally:
        server.close()
