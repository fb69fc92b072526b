"""`parsimony bench`: its figures as JSON and as a table, and a robot description that cannot be
used stops the bench before any timing, with one line naming the file and what is wrong."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from studies.goal_sets import LAWS, POSITION_LAWS
from tests.parsimony.cli_process import run_cli
from tests.parsimony.in_process import run_in_process


def test_a_description_that_cannot_be_used_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("arm: 3\n")
    code, out, err = run_in_process(["bench", "--zoo-only", "--zoo", str(bad)], capsys)
    assert code == 2 and out == ""
    [line] = err.strip().splitlines()
    assert line.startswith(f"parsimony bench: {bad}: arm")


def standard_json(text: str):
    """``text`` parsed as standard JSON, which has no NaN or Infinity (Python writes them)."""

    def refuse(constant: str):
        raise ValueError(f"{constant} is not JSON")

    return json.loads(text, parse_constant=refuse)


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
