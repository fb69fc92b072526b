"""Fixtures for deploy tests: profiles on free loopback ports and launcher processes."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from profiles.endpoints import free_port

DEADLINE_S = 60.0
"""Generous limit for anything that starts processes on a loaded machine."""

LAUNCH = (
    "import argparse, sys\n"
    "from parsimony.commands import launch\n"
    "root = argparse.ArgumentParser(prog='parsimony')\n"
    "launch.add_parser(root.add_subparsers())\n"
    "sys.exit(launch.run(root.parse_args(['launch', *sys.argv[1:]])))\n"
)
"""`parsimony launch` through its own module, independent of the other subcommands."""


def profile_file(directory: Path, components: list[dict[str, Any]], **top_level: Any) -> Path:
    """Write a profile of namespace ``test`` with its router on a free loopback port."""
    data = {
        "namespace": "test",
        "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
        "components": components,
        **top_level,
    }
    path = directory / f"profile{len(list(directory.glob('*.yaml')))}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


ProfileWriter = Callable[..., Path]


@pytest.fixture
def write_profile(tmp_path: Path) -> ProfileWriter:
    """``write_profile(components, **top_level)``: a profile file on a free loopback port."""
    return lambda components, **top_level: profile_file(tmp_path, components, **top_level)


class Launched:
    """A running `parsimony launch`, its output lines timestamped as they arrive."""

    def __init__(self, profile: Path, *args: str) -> None:
        command = [sys.executable, "-c", LAUNCH, str(profile), *args]
        self.process = subprocess.Popen(
            command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
        )
        self.lines: list[tuple[float, str]] = []
        self._changed = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            with self._changed:
                self.lines.append((time.monotonic(), line.rstrip("\n")))
                self._changed.notify_all()

    def text(self) -> str:
        """All output so far."""
        with self._changed:
            return "\n".join(line for _, line in self.lines)

    def wait_for(
        self, pattern: str, after: int = 0, timeout_s: float = DEADLINE_S
    ) -> tuple[int, float, re.Match[str]]:
        """The first line at index >= ``after`` matching ``pattern``: (index, time, match)."""
        regex = re.compile(pattern)

        def found() -> tuple[int, float, re.Match[str]] | None:
            for index in range(after, len(self.lines)):
                stamp, line = self.lines[index]
                match = regex.search(line)
                if match:
                    return index, stamp, match
            return None

        with self._changed:
            if not self._changed.wait_for(lambda: found() is not None, timeout_s):
                pytest.fail(f"no line matching {pattern!r} within {timeout_s} s:\n{self.text()}")
            result = found()
            assert result is not None
            return result

    def stop(self, signum: int = signal.SIGINT) -> int:
        """Send ``signum`` to the launcher and return its exit code."""
        self.process.send_signal(signum)
        code = self.process.wait(DEADLINE_S)
        self._reader.join(DEADLINE_S)
        return code

    def child_pids(self) -> list[int]:
        """Every component pid the launcher reported starting."""
        return [int(pid) for pid in re.findall(r"\] started \w+ \(.*, pid (\d+)\)", self.text())]

    def shut_down(self) -> None:
        """Teardown: SIGTERM the launcher (it stops its children), SIGKILL if it hangs.

        Children of a killed launcher stop by themselves once their parent is gone.
        """
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(DEADLINE_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()


LaunchFixture = Callable[..., Launched]


@pytest.fixture
def launch() -> Iterator[LaunchFixture]:
    """``launch(profile, *args)``: start `parsimony launch`; it is shut down at teardown."""
    started: list[Launched] = []

    def start(profile: Path, *args: str) -> Launched:
        started.append(Launched(profile, *args))
        return started[-1]

    yield start
    for launched in started:
        launched.shut_down()


@pytest.fixture(scope="module")
def running_pub(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """One launched profile per test module, with a scripted publisher `pub` alive.

    The launcher must still stop cleanly (exit 0) after the module's tests.
    """
    pub = {"name": "pub", "module": "scripted_publisher", "role": "tool"}
    profile = profile_file(
        tmp_path_factory.mktemp("running"), [{**pub, "params": {"rate_hz": 50.0}}]
    )
    launched = Launched(profile)
    try:
        launched.wait_for(r"\[launch\] pub alive")
        yield profile
        assert launched.stop(signal.SIGTERM) == 0
    finally:
        launched.shut_down()


def publisher(name: str, role: str = "tool", **fields: object) -> dict[str, object]:
    """A scripted publisher component that restarts quickly."""
    return {
        "name": name,
        "module": "scripted_publisher",
        "role": role,
        "params": {"rate_hz": 20.0},
        "restart": {"backoff_initial_s": 0.1},
        **fields,
    }
