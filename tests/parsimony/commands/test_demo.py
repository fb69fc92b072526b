"""`parsimony demo`: every experiment reported and exit 0, its JSON alone on stdout (the demo is
run once for the module)."""

from __future__ import annotations

import json
import subprocess

import pytest

from tests.parsimony.cli_process import run_cli


@pytest.fixture(scope="module")
def demo() -> subprocess.CompletedProcess[str]:
    """`parsimony demo --json`, once for the module."""
    return run_cli("demo", "--json")


def test_demo_reports_every_experiment_and_exits_zero(demo: subprocess.CompletedProcess[str]):
    assert demo.returncode == 0, demo.stdout + demo.stderr
    rows = {(row["experiment"], row["law"]): row for row in json.loads(demo.stdout)}
    assert rows[("pose", "LP")]["converged"] and rows[("position", "LP")]["converged"]
    for law in ("LP vector field", "LP border"):
        assert rows[("obstacle", law)]["converged"]
        assert rows[("obstacle", law)]["min_obstacle_clearance"] > 0.0
    assert rows[("joint limit", "pinv")]["worst_joint_overrun"] > 0.0
    assert rows[("joint limit", "LP")]["worst_joint_overrun"] == 0.0
    guarded, blind = rows[("table", "LP")], rows[("table", "LP without arm rows")]
    assert guarded["converged"] and guarded["arm_penetrations"] == 0
    assert guarded["min_arm_clearance"] > 0.0
    assert blind["arm_penetrations"] > 0 and blind["min_arm_clearance"] < 0.0


def test_json_commands_print_nothing_but_json(demo: subprocess.CompletedProcess[str]):
    """The whole of stdout parses, whatever a library prints (HiGHS 1.16 prints a banner)."""
    for result in (demo, run_cli("schema")):
        assert result.returncode == 0, result.stderr
        json.loads(result.stdout)
