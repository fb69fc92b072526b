"""`parsimony reproduce` as a user runs it: every result of chapter 6 is a row beside the
dissertation's value, every law says what it ran, every figure is written, and every result
that does not depend on the clock equals the golden one (tests/studies/reproduce_golden.json, within
its tolerance): a change of result fails here and is a decision, not an accident.

``python -m tests.studies.test_reproduce --write`` runs the command and writes the golden
results anew.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from studies.reproduce import NOTES, TABLE_6_1

pytestmark = pytest.mark.heavy  # two runs of minutes each
GOLDEN = Path(__file__).with_name("reproduce_golden.json")
TRIALS = 2
"""Trials of section 6.3 in the test: its timed rows are checked for form alone."""
SECTIONS = ("6.2.1", "6.2.2", "6.2.3", "table 6.1", "6.3", "7.2 (1)", "7.2 (5)")


def run_reproduce(out: Path) -> dict:
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "parsimony.cli",
            "reproduce",
            "--json",
            "--trials",
            str(TRIALS),
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)  # the JSON alone on stdout


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> dict:
    out = tmp_path_factory.mktemp("reproduce")
    return {**run_reproduce(out), "out": out}


def same(ours: Any, golden: Any, tolerance: dict[str, float], where: str) -> None:
    """``ours`` equals ``golden``: floats within the tolerance, everything else exactly."""
    if isinstance(golden, dict):
        assert isinstance(ours, dict) and ours.keys() == golden.keys(), (where, ours, golden)
        for key in golden:
            same(ours[key], golden[key], tolerance, f"{where}.{key}")
    elif isinstance(golden, list):
        assert isinstance(ours, list) and len(ours) == len(golden), (where, ours, golden)
        for index, (a, b) in enumerate(zip(ours, golden, strict=True)):
            same(a, b, tolerance, f"{where}[{index}]")
    elif isinstance(golden, float) and not isinstance(golden, bool):
        assert isinstance(ours, int | float) and (
            math.isnan(golden) and math.isnan(ours) or ours == pytest.approx(golden, **tolerance)
        ), (where, ours, golden)
    else:
        assert ours == golden, (where, ours, golden)


def test_every_result_that_does_not_depend_on_the_clock_equals_the_golden_one(report: dict) -> None:
    golden = json.loads(GOLDEN.read_text())
    rows = {row["key"]: row for row in report["rows"]}
    assert len(rows) == len(report["rows"]), "row keys must be unique"
    untimed = {key for key, row in rows.items() if not row["timed"]}
    assert untimed == golden["rows"].keys(), untimed ^ golden["rows"].keys()
    for key, ours in golden["rows"].items():
        same(rows[key]["ours"], ours, golden["tolerance"], key)


def test_every_chapter_6_result_is_a_row_and_every_law_says_what_it_ran(report: dict) -> None:
    rows = report["rows"]
    assert {row["section"] for row in rows} == set(SECTIONS)
    for row in rows:
        assert row["ours"] is not None and row["dissertation"] is not None, row
    ran = {(law["experiment"], law["label"]): law["ran"] for law in report["laws"]}
    assert all(text for text in ran.values())
    for row in rows:
        assert row["experiment"], row["key"]
        assert row["laws"] or row["key"].endswith(".least_residual"), row["key"]
        for experiment in row["experiment"].split(", "):
            for label in row["laws"]:
                assert (experiment, label) in ran, row["key"]
    assert "none (5.29 exactly)" in ran["pose", "LP 5.29"]
    assert "5.28 (lambda 2, on the axle centre" in ran["obstacle", "LP 5.29"]
    assert "5.10" in ran["obstacle", "LP 5.29"] and "circulation" not in ran["obstacle", "LP 5.29"]
    assert "saturated" in ran["pose", "cascade, saturated"]
    assert ran["6.3 test 1", "LP"].startswith("min ||J u + eta e||_1, eta 5, subject to 5.10")


def test_table_6_1_quotes_the_dissertation_and_compares_with_its_text(report: dict) -> None:
    table = [row for row in report["rows"] if row["section"] == "table 6.1"]
    for task, laws in TABLE_6_1.items():
        ratios = [row for row in table if row["key"].startswith(f"{task}.ratio.")]
        assert len(ratios) == 6, task
        for row in ratios:
            quoted = zip(laws["LP"], laws["PINV"], strict=True)
            assert row["dissertation"] == [lp / pinv for lp, pinv in quoted]
            assert row["direction"].startswith("< 1, > 1, < 1, > 1")
        contradicted = "the dissertation's own table has < 1" in ratios[0]["direction"]
        assert contradicted == (task == "pose")


def test_the_timed_rows_say_their_trials_and_percentiles(report: dict) -> None:
    timed = {row["key"]: row for row in report["rows"] if row["timed"]}
    for test in ("test 1", "test 2"):
        row = timed[f"6.3.{test}.time"]
        assert row["ours"]["trials"] == TRIALS and row["dissertation"]["trials"] == 10000
    steps = [row for key, row in timed.items() if key.startswith("step_time.")]
    assert len(steps) == 4 and all(row["ours"]["p99"] > 0 for row in steps)


def test_every_figure_is_written_and_noted(report: dict) -> None:
    for path in report["figures"]:
        assert Path(path).stat().st_size > 1000, path
    out = report["out"]
    notes = (out / "NOTES.md").read_text()
    for name in NOTES:
        assert (out / name).is_file() and f"`{name}`" in notes


def write_golden(out: Path) -> None:
    """Run the command and keep every untimed row's result as the golden one."""
    found = run_reproduce(out)
    GOLDEN.write_text(
        json.dumps(
            {
                "tolerance": {"rel": 1e-3, "abs": 1e-6},
                "rows": {row["key"]: row["ours"] for row in found["rows"] if not row["timed"]},
            },
            indent=1,
        )
        + "\n"
    )


if __name__ == "__main__" and sys.argv[1:] == ["--write"]:
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        write_golden(Path(folder))
