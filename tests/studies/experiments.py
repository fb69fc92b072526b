"""Runs of `parsimony experiment` for the tests of the whole simulated loop: as a user types it (a
process of its own, its report on stdout) or as the command runs it (``run_experiment`` in the
test's process: the same launch, loop, recording and judgement, without a Python start), and what
every sound run of the LP shows."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

from outputs.stdout import json_text
from studies.experiment import Options, run_experiment

ONE_DEGREE = math.radians(1.0)


def experiment(out: Path, *arguments: str, stderr: list[str] | None = None) -> tuple[int, dict]:
    """Run `parsimony experiment ... --json`; its exit status and the report on its stdout
    (its stderr's lines added to ``stderr``)."""
    command = [sys.executable, "-m", "parsimony.cli", "experiment", *arguments, "--json"]
    done = subprocess.run(
        [*command, "--out", str(out)], capture_output=True, text=True, timeout=300
    )
    assert done.stdout.strip(), done.stderr[-2000:]
    if stderr is not None:
        stderr += done.stderr.splitlines()
    report = json.loads(done.stdout)
    assert report == json.loads((out / "report.json").read_text())
    return done.returncode, report


def run_here(out: Path, name: str, **options: Any) -> dict:
    """Experiment ``name`` with ``options`` (``studies.experiment.Options``) run by the command's
    own function in this process: its report, as written to ``out/report.json``. Its figures
    are drawn only if asked (``figures=True``): a few seconds of CPU each run."""
    options.setdefault("figures", False)
    report = json.loads(json_text(run_experiment(Options(name, out=out, **options))))
    assert report == json.loads((out / "report.json").read_text())
    return report


def assert_sound(report: dict) -> None:
    """What every converged run of the LP must show."""
    assert report["converged"], report
    assert report["contacts"] == 0
    assert report["joint_limit_violations"] == 0
    assert report["final_error"] < 0.02
    error = report["estimator_error"]
    assert error["samples"] > 50  # states of the steady state, 50 Hz
    assert error["position_m"] < 0.01 and error["angle_rad"] < ONE_DEGREE, error
