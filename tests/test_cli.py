"""The `parsimony` command as a user runs it: a real process."""

from __future__ import annotations

import json
import subprocess
import sys

from parsimony.cli import COMMANDS


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "parsimony.cli", *args],
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_help_lists_every_subcommand():
    result = run_cli("--help")
    assert result.returncode == 0
    for name in COMMANDS:
        assert name in result.stdout


def test_bench_prints_step_times_and_the_convergence_test_as_json():
    result = run_cli("bench", "--repeats", "50", "--trials", "1", "--goals", "0")
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout.splitlines()[0])
    for law in ("lp", "classic", "cascade", "kinematics"):
        assert 0.0 < report["step"][law]["median_us"] <= report["step"][law]["p99_us"]
    assert report["ratios"]["lp_over_classic"] > 0.0
    for test in ("holonomic/classic", "holonomic/lp", "nonholonomic/cascade", "nonholonomic/lp"):
        assert report["convergence"][test]["converged_trials"] == 1
    assert "lp_over_classic" in result.stdout


def test_demo_reports_every_experiment_and_exits_zero():
    result = run_cli("demo", "--json")
    assert result.returncode == 0, result.stdout + result.stderr
    rows = {(row["experiment"], row["law"]): row for row in json.loads(result.stdout)}
    assert rows[("pose", "LP")]["converged"] and rows[("position", "LP")]["converged"]
    assert rows[("obstacle", "LP border")]["min_obstacle_clearance"] > 0.0
    assert rows[("joint limit", "pinv")]["worst_joint_overrun"] > 0.0
    assert rows[("joint limit", "LP")]["worst_joint_overrun"] == 0.0
