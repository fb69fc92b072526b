"""Fixtures for runtime tests: a profile on a free loopback port, its router, and helpers."""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Generic, TypeVar

import pytest
import yaml
import zenoh
from pydantic import BaseModel

from launch.fork_server import ForkServer, Served
from messages import codec, topics
from profiles.deploy_files import DEPLOY
from profiles.endpoints import free_port
from profiles.profile import Profile, load_profile
from profiles.profile_files import read_profile_data

M = TypeVar("M", bound=BaseModel)

DEADLINE_S = 60.0
"""Generous limit for anything that involves starting a process on a loaded machine."""

COMPONENT_MODULES = sorted(
    f"components.{path.stem}"
    for path in (Path(__file__).resolve().parents[2] / "components").glob("*.py")
    if "run_component(" in path.read_text()
)
"""Every component's module, which the tests' fork server loads."""


@pytest.fixture(scope="session")
def component_server() -> Iterator[ForkServer]:
    """One fork server per test process (``launch.fork_server``) with every component module
    loaded: a component's process starts as a launcher starts it, without an interpreter's
    start (half a second of CPU)."""
    server = ForkServer(COMPONENT_MODULES)
    yield server
    server.close()


def _wait_until(condition: Callable[[], bool], what: str, timeout_s: float = DEADLINE_S) -> None:
    """Return once ``condition()`` holds; fail the test after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout_s} s waiting for {what}")
        time.sleep(0.005)


WaitUntil = Callable[..., None]


@pytest.fixture
def wait_until() -> WaitUntil:
    """``wait_until(condition, what, timeout_s=10)``: poll a condition against a deadline."""
    return _wait_until


@dataclass
class System:
    """A profile written to disk with its router open."""

    path: Path
    profile: Profile
    router: zenoh.Session
    deadline_s: float = DEADLINE_S
    server: ForkServer | None = None
    """Where its component processes are forked (None: each a new interpreter)."""
    processes: list[subprocess.Popen[str] | Served] = field(default_factory=list)

    def liveliness(self) -> LivelinessLog:
        """Start recording the liveliness changes of the namespace."""
        return LivelinessLog(self.router, self.profile.namespace)

    def inbox(self, topic: topics.Topic[M]) -> Inbox[M]:
        """Start collecting the messages of ``topic`` in the namespace."""
        return Inbox(self.router, self.profile.namespace, topic)

    def start(self, name: str) -> subprocess.Popen[str] | Served:
        """Start the profile's component ``name`` as its own process (forked by the server, if
        the system has one); what it logs goes to ``<name>.log`` beside the profile (a pipe
        nobody reads would block it once full)."""
        module = self.profile.component(name).module_path
        command = [module, "--profile", str(self.path), "--name", name]
        with (self.path.parent / f"{name}.log").open("a") as log:
            served = self.server.spawn(command, stderr=log) if self.server else None
            process = served or subprocess.Popen([sys.executable, "-m", *command], stderr=log)
        self.processes.append(process)
        return process

    def log(self, name: str) -> str:
        """What component ``name`` has logged so far."""
        return (self.path.parent / f"{name}.log").read_text()

    def stop_processes(self) -> None:
        """Teardown: SIGTERM every process started, SIGKILL those that do not stop."""
        for process in self.processes:
            if process.poll() is None:
                process.terminate()
        for process in self.processes:
            try:
                process.wait(self.deadline_s)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


@pytest.fixture
def system(tmp_path: Path, component_server: ForkServer) -> Iterator[System]:
    """Namespace ``test``: ``pub`` (a scripted publisher process) and in-process nodes."""
    in_process = {"module": "scripted_publisher", "role": "tool", "enabled": False}
    data = {
        "namespace": "test",
        "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
        "components": [
            {
                "name": "pub",
                "module": "scripted_publisher",
                "role": "tool",
                "params": {"rate_hz": 50.0, "base_x": 1.5, "goal_task": "pose"},
            },
            {"name": "talker", **in_process},
            {"name": "listener", **in_process},
        ],
    }
    path = tmp_path / "test.yaml"
    path.write_text(yaml.safe_dump(data))
    profile = load_profile(path)
    with zenoh.open(profile.zenoh.router_config()) as router:
        system = System(path, profile, router, server=component_server)
        yield system
        system.stop_processes()


def _deployer(
    stack: ExitStack, directory: Path, server: ForkServer
) -> Callable[[str | Path], System]:
    """``deploy(profile)``: a profile of ``deploy/`` (its path, or its YAML text) copied into
    ``directory`` with its router open until ``stack`` closes.

    The copy's router moves to a free loopback port and its robot path becomes absolute
    (the copy lives in a temporary directory); nothing else changes. The processes
    started are stopped when ``stack`` closes.
    """

    def deploy(profile: str | Path) -> System:
        if isinstance(profile, Path):
            data: dict[str, Any] = read_profile_data(profile)
        else:
            data = yaml.safe_load(profile)
            data["robot"] = str(DEPLOY / data["robot"])
        data["zenoh"]["router"] = [f"tcp/127.0.0.1:{free_port()}"]
        path = directory / f"deployed{len(list(directory.glob('*.yaml')))}.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False))
        profile = load_profile(path)
        router = stack.enter_context(zenoh.open(profile.zenoh.router_config()))
        system = System(path, profile, router, server=server)
        stack.callback(system.stop_processes)
        return system

    return deploy


@pytest.fixture
def deployed(
    tmp_path: Path, component_server: ForkServer
) -> Iterator[Callable[[str | Path], System]]:
    """``deployed(profile)``: a profile of ``deploy/`` with its router open, for one test
    (``_deployer``)."""
    with ExitStack() as stack:
        yield _deployer(stack, tmp_path, component_server)


@pytest.fixture(scope="module")
def deployed_for_module(
    tmp_path_factory: pytest.TempPathFactory, component_server: ForkServer
) -> Iterator[Callable[[str | Path], System]]:
    """``deployed`` for a system the tests of a module share (started once)."""
    with ExitStack() as stack:
        yield _deployer(stack, tmp_path_factory.mktemp("deployed"), component_server)


class LivelinessLog:
    """Every liveliness change of a namespace, as (component, alive) in arrival order."""

    def __init__(self, session: zenoh.Session, namespace: str) -> None:
        self.namespace = namespace
        self.events: list[tuple[str, bool]] = []
        self._changed = threading.Condition()
        self._subscriber = session.liveliness().declare_subscriber(
            topics.liveliness_selector(namespace), self._on_sample, history=True
        )

    def _on_sample(self, sample: zenoh.Sample) -> None:
        name = topics.component_of_liveliness_key(self.namespace, str(sample.key_expr))
        with self._changed:
            self.events.append((name, sample.kind == zenoh.SampleKind.PUT))
            self._changed.notify_all()

    def wait_for(
        self, name: str, alive: bool, after: int = 0, timeout_s: float = DEADLINE_S
    ) -> int:
        """Wait for ``name`` to become alive (or lost) at index >= ``after``; return the index."""

        def found() -> int | None:
            for index in range(after, len(self.events)):
                if self.events[index] == (name, alive):
                    return index
            return None

        with self._changed:
            if not self._changed.wait_for(lambda: found() is not None, timeout_s):
                state = "alive" if alive else "lost"
                pytest.fail(f"{name} not {state} within {timeout_s} s; saw {self.events}")
            return found()


class Inbox(Generic[M]):
    """Every message of one topic that reaches a session; payloads that fail to decode
    (a non-finite float, say) are kept in ``undecodable``."""

    def __init__(self, session: zenoh.Session, namespace: str, topic: topics.Topic[M]) -> None:
        self.topic = topic
        self.messages: list[M] = []
        self.undecodable: list[str] = []
        self._changed = threading.Condition()
        self._subscriber = session.declare_subscriber(topic.key(namespace), self._on_sample)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        with self._changed:
            try:
                self.messages.append(codec.decode(sample.payload.to_bytes(), self.topic.type))
            except codec.DecodeError as error:
                self.undecodable.append(str(error))
            self._changed.notify_all()

    def wait_for(self, match: Callable[[M], bool], what: str, timeout_s: float = DEADLINE_S) -> M:
        """The first message that ``match`` accepts, waiting for it up to ``timeout_s``."""
        with self._changed:
            found = self._changed.wait_for(
                lambda: next((m for m in self.messages if match(m)), None), timeout_s
            )
        if found is None:
            pytest.fail(f"no {self.topic.name} {what} within {timeout_s} s")
        return found
