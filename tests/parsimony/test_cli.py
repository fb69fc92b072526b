"""The `parsimony` command as a user runs it: a real process (what it refuses before it runs
anything: its entry point in the test's process, tests/parsimony/in_process.py)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from parsimony.cli import COMMANDS
from studies.goal_sets import LAWS, POSITION_LAWS
from tests.parsimony.in_process import run_in_process


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "parsimony.cli", *args],
        capture_output=True,
        text=True,
        timeout=300,
    )


def standard_json(text: str):
    """``text`` parsed as standard JSON, which has no NaN or Infinity (Python writes them)."""

    def refuse(constant: str):
        raise ValueError(f"{constant} is not JSON")

    return json.loads(text, parse_constant=refuse)


def test_help_lists_every_subcommand():
    result = run_cli("--help")
    assert result.returncode == 0
    for name in COMMANDS:
        assert name in result.stdout


@pytest.mark.heavy  # minutes: every law's steps, convergence and goal sets
def test_bench_prints_step_times_and_the_convergence_test_as_json():
    """One goal per family and law, the zoo's step times on one robot (every figure's form is
    checked; the numbers are the bench's to say)."""
    zoo = "deploy/robots/youbot.yaml"
    result = run_cli(
        "bench", "--json", "--repeats", "50", "--trials", "1", "--goals", "1", "--zoo", zoo
    )
    assert result.returncode == 0, result.stderr
    report = standard_json(result.stdout)  # a median of no steps is null
    assert list(report["zoo"]) == ["youbot"]
    for law in ("lp", "qp", "classic", "cascade", "kinematics"):
        assert 0.0 < report["step"][law]["median_us"] <= report["step"][law]["p99_us"]
    assert report["ratios"]["lp_over_classic"] > 0.0 and report["ratios"]["qp_over_classic"] > 0
    for name in ("lp_with_arm_rows", "lp_without_arm_rows", "arm_rows"):
        figures = report["arm_rows"][name]
        assert 0.0 < figures["median_us"] <= figures["p99_us"]
        assert 0.0 < figures["cpu_median_us"] <= figures["cpu_p99_us"]
    assert report["ratios"]["lp_with_arm_rows_over_without"] > 0.0
    assert report["ratios"]["lp_with_arm_rows_over_without_cpu"] > 0.0
    parts = report["lp_breakdown_us"]
    assert {"kinematics", "rows", "vertex", "highs", "glue", "highs_runs"} <= parts.keys()
    assert min(parts["kinematics"], parts["rows"], parts["vertex"]) > 0.0
    assert 0.0 < parts["highs_runs"] <= 1.0  # the first step of each pass calls HiGHS
    for test in ("holonomic/classic", "holonomic/lp", "nonholonomic/cascade", "nonholonomic/lp"):
        assert report["convergence"][test]["converged_trials"] == 1
    for family in ("ahead", "anywhere"):
        laws = report["goals"][f"{family} pose"]["laws"]
        assert laws.keys() == set(LAWS)
        for row in laws.values():
            assert (
                row["reached"]
                >= row["within_joint_limits"]
                >= (row["within_joint_and_speed_limits"])
            )
            assert sum(row["nonzero_histogram"]) == sum(row["practical_histogram"]) > 0
        supervised = laws["lp + staging supervisor"]
        assert supervised["plans_per_run"] >= 1.0
        assert 0.0 < supervised["plan_median_ms"] <= supervised["plan_p99_ms"]
        position = report["goals"][f"{family} position"]["laws"]
        assert position.keys() == set(POSITION_LAWS)
        assert 1.0 <= position["lp"]["median_nonzero_moving"] <= 8.0
    assert "bench:" in result.stderr  # progress goes to stderr


def test_bench_table_names_each_figure():
    result = run_cli("bench", "--repeats", "20", "--trials", "1", "--goals", "0")
    assert result.returncode == 0, result.stderr
    assert "lp_over_classic" in result.stdout and "LP step, median us by part" in result.stdout


def test_json_commands_print_nothing_but_json(demo: subprocess.CompletedProcess[str]):
    """The whole of stdout parses, whatever a library prints (HiGHS 1.16 prints a banner)."""
    for result in (demo, run_cli("schema")):
        assert result.returncode == 0, result.stderr
        json.loads(result.stdout)


def test_a_library_writing_to_file_descriptor_1_reaches_stderr():
    """What C code writes to fd 1 while a command runs is routed to stderr, not the result."""
    code = (
        "import os, sys\n"
        "from outputs.stdout import emit, result_only_stdout\n"
        "with result_only_stdout():\n"
        "    os.write(1, b'banner from C\\n')\n"
        "    print('a log line')\n"
        "    emit('{\"result\": 1}')\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout) == {"result": 1}
    assert "banner from C" in result.stderr and "a log line" in result.stderr


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


@pytest.mark.parametrize("duration", ["nan", "inf", "-1", "0", "soon"])
def test_launch_refuses_a_duration_that_is_not_a_positive_number_of_seconds(duration, capsys):
    code, _, err = run_in_process(
        ["launch", "deploy/controllers.yaml", "--duration", duration], capsys
    )
    assert code == 2
    assert "--duration" in err and repr(duration) in err


def test_status_of_a_misspelt_profile_says_the_file_does_not_exist():
    result = run_cli("status", "deploy/controlers.yaml")
    assert result.returncode == 2
    assert "deploy/controlers.yaml: no such profile file" in result.stderr


def test_zenoh_errors_reach_the_user_as_one_readable_line():
    result = run_cli("status", "test", "--router", "tcp/127.0.0.1:1", "--timeout", "0.5")
    assert result.returncode == 2
    assert "cannot reach a router at tcp/127.0.0.1:1" in result.stderr
    assert ".rs:" not in result.stderr and len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("argv", "error"),
    [
        (("0.5", "nan", "0.4"), "argument Y: expected a finite number, got 'nan'"),
        (("0.5", "0", "0.4", "--position", "--yaw", "30"), "--position takes no --yaw or --rpy"),
        (("0.5", "0", "0.4", "--yaw", "10", "--rpy", "0", "0", "10"), "not allowed with"),
        (
            ("0.5", "0", "0.4", "--wait", "--profile", "deploy/sim.yaml"),
            "--wait follows supervisor/status, and no component of deploy/sim.yaml writes it",
        ),
    ],
)
def test_goal_refuses_input_it_cannot_use_with_exit_2(
    argv: tuple[str, ...], error: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before anything is sent, and with no running system to ask."""
    code, _, err = run_in_process(["goal", *argv], capsys)
    assert code == 2 and error in err, err
