"""Fixtures for runtime tests: a profile on a free loopback port, its router, and helpers."""

from __future__ import annotations

import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml
import zenoh

from deploy.profile import Profile, load_profile
from messages import topics

DEADLINE_S = 10.0
"""Generous limit for anything that involves starting a process on a loaded machine."""


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


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

    def liveliness(self) -> LivelinessLog:
        """Start recording the liveliness changes of the namespace."""
        return LivelinessLog(self.router, self.profile.namespace)

    def start(self, name: str) -> subprocess.Popen[str]:
        """Start the profile's component ``name`` as its own process."""
        module = self.profile.component(name).module_path
        command = [sys.executable, "-m", module, "--profile", str(self.path), "--name", name]
        return subprocess.Popen(command, stderr=subprocess.PIPE, text=True)


@pytest.fixture
def system(tmp_path: Path) -> Iterator[System]:
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
        yield System(path, profile, router)


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
