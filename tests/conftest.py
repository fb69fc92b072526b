"""How the suite runs in parallel (pytest-xdist, ``--dist loadfile``: see the Makefile), and the
whole-loop runs its files share.

Each test file runs on one worker, so a set-up it shares between its tests (a module-scoped
fixture: a launched system, a recorded run) runs once. Tests marked ``heavy`` (minutes each)
are handed out first, so none of them starts last and finishes after all the others. A run
several files read (``pose_lp_run``) is made once per suite, whichever worker asks first, and
read by the others (pytest-xdist's way: a file lock in the folder the workers share).
"""

from __future__ import annotations

import fcntl
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest


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
