"""messages.process: how a component process is started, stopped, and told of its parent and
of the launch's runtime directory."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from messages.process import (
    PARENT_PID_ENV,
    RUNTIME_DIR_ENV,
    command,
    params_file,
    parent_gone,
    runtime_dir,
    stop,
)


def test_a_process_knows_when_the_parent_that_named_itself_is_gone(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv(PARENT_PID_ENV, raising=False)
    assert not parent_gone()  # started by no one who named itself: never gone
    monkeypatch.setenv(PARENT_PID_ENV, str(os.getppid()))
    assert not parent_gone()
    monkeypatch.setenv(PARENT_PID_ENV, str(os.getppid() + 1))  # now another's child
    assert parent_gone()


def test_parameters_are_kept_in_the_launchs_runtime_directory(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.delenv(RUNTIME_DIR_ENV, raising=False)
    assert runtime_dir() is None and params_file("arm") is None
    monkeypatch.setenv(RUNTIME_DIR_ENV, "")
    assert runtime_dir() is None and params_file("arm") is None
    monkeypatch.setenv(RUNTIME_DIR_ENV, str(tmp_path))
    assert runtime_dir() == tmp_path
    assert params_file("arm") == tmp_path / "arm.json"


def test_a_component_runs_its_module_with_this_python_its_profile_and_name() -> None:
    assert command("components.arm_driver", Path("deploy/sim.yaml"), "arm") == [
        sys.executable,
        "-m",
        "components.arm_driver",
        "--profile",
        "deploy/sim.yaml",
        "--name",
        "arm",
    ]


def test_stop_gives_the_exit_code_of_a_child_that_obeys_the_signal() -> None:
    child = subprocess.Popen(["sleep", "60"])
    assert stop(child, signal.SIGTERM, None) == -signal.SIGTERM


def test_stop_kills_a_child_that_ignores_the_signal() -> None:
    child = subprocess.Popen(
        ["sh", "-c", "trap '' TERM; echo ready; exec sleep 60"], stdout=subprocess.PIPE, text=True
    )
    assert child.stdout is not None and child.stdout.readline() == "ready\n"  # TERM ignored now
    assert stop(child, signal.SIGTERM, 0.05) == -signal.SIGKILL
    child.stdout.close()
