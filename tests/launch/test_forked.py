"""A module run in a forked child (launch/forked.py): its output, its exit code, and the child
seen as a Popen (poll, wait with a timeout, signals)."""

from __future__ import annotations

import signal
import subprocess
from pathlib import Path

import pytest

from launch.forked import forked


def test_a_forked_child_runs_its_module_and_answers_as_a_popen(tmp_path: Path) -> None:
    with (tmp_path / "out.log").open("w") as log:
        child = forked(["platform"], stdout=log, stderr=subprocess.STDOUT)
        assert child.wait(60) == 0 and child.poll() == 0
    assert (tmp_path / "out.log").read_text().startswith("Linux")
    with (tmp_path / "error.log").open("w") as log:
        assert forked(["no_such_module_here"], stdout=log, stderr=log).wait(60) == 1
    assert "No module named no_such_module_here" in (tmp_path / "error.log").read_text()


def test_a_forked_child_waited_for_too_briefly_is_stopped_by_a_signal() -> None:
    child = forked(
        ["timeit", "-n1", "-r1", "import time; time.sleep(60)"], stdout=subprocess.DEVNULL
    )
    with pytest.raises(subprocess.TimeoutExpired):
        child.wait(0.05)
    assert child.poll() is None
    child.send_signal(signal.SIGINT)  # Python's KeyboardInterrupt, as in a new interpreter
    assert child.wait(60) != 0
    child.kill()  # gone already: nothing to do
