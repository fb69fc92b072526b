"""How the suite runs in parallel (pytest-xdist, ``--dist loadfile``: see the Makefile), and the
whole-loop runs its files share.

Each test file runs on one worker, so a set-up it shares between its tests (a module-scoped
fixture: a launched system, a recorded run) runs once. Tests marked ``heavy`` (minutes each)
are handed out first, so none of them starts last and finishes after all the others. A run
several files read (``pose_lp_run``) is made once per suite, whichever worker asks first, and
read by the others (pytest-xdist's way: a file lock in the folder the workers share).

The run keeps the bytecode it compiles (``keep_bytecode``): it starts hundreds of Python
processes (launches, components, commands), each of which would otherwise compile the project
and the test modules again where the environment forbids writing it (PYTHONDONTWRITEBYTECODE).
"""

from __future__ import annotations

import fcntl
import os
import shutil
import sys
from collections.abc import Callable
from pathlib import Path

import pytest


def keep_bytecode() -> None:
    """Where PYTHONDONTWRITEBYTECODE forbids writing bytecode beside the sources, write it in
    the virtual environment's ``pycache`` instead (Python's PYTHONPYCACHEPREFIX), for this
    process and the processes it starts: each compiles a module once, not once a process."""
    if not sys.dont_write_bytecode or sys.prefix == sys.base_prefix:  # not in a venv: as is
        return
    prefix = sys.pycache_prefix or str(Path(sys.prefix) / "pycache")
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    os.environ["PYTHONPYCACHEPREFIX"] = prefix
    sys.pycache_prefix, sys.dont_write_bytecode = prefix, False


keep_bytecode()  # before the test modules are collected (and their asserts rewritten)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    items.sort(key=lambda item: item.get_closest_marker("heavy") is None)  # stable


def shared(factory: pytest.TempPathFactory, name: str, make: Callable[[Path], None]) -> Path:
    """The folder ``make`` filled, made once per suite run under a lock: by the first worker
    that asks, read by the others (read-only: a test that changes a file copies it first)."""
    base = factory.getbasetemp()
    if base.name.startswith("popen-gw"):  # a worker of pytest-xdist: its siblings share
        base = base.parent
    folder, done = base / "shared" / name, base / "shared" / f"{name}.done"
    folder.parent.mkdir(exist_ok=True)
    with (base / "shared" / f"{name}.lock").open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        if not done.exists():
            shutil.rmtree(folder, ignore_errors=True)  # what a failed make left
            folder.mkdir()
            make(folder)
            done.touch()
    return folder


@pytest.fixture(scope="session")
def pose_lp_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The lockstep pose experiment of seed 6 with the LP, run to its end and recorded (as the
    command runs it, in the test's process): its folder (report.json, session.mcap,
    profile.yaml, launch.log). Read by the tests of recording, rerun and replay."""

    from tests.studies.experiments import run_here  # (not at every test's collection)

    def make(out: Path) -> None:
        report = run_here(out, "pose", seed=6, controller="lp")
        assert report["converged"] and report["mode"] == "lockstep", report

    return shared(tmp_path_factory, "pose_lp_seed6", make)
