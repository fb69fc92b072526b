"""A study driven to its results file on the local pool: only the runs the file lacks run (a
row already there keeps its figures, under the index the study gives it now); a run that
fails is tried once more, after the others, and its row says so; the counts say what ran."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from profiles.deploy_files import ROBOT_FILE
from studies.study import results
from studies.study.drive import drive
from studies.study.local import LocalPool
from studies.study.schema import Study
from studies.study.sweep import expand


def runs(**changes: object):
    study = Study.model_validate(
        {
            "name": "tiny",
            "robots": [str(ROBOT_FILE)],
            "families": ["ahead"],
            "goals": 2,
            "seeds": [2],
            "laws": [{"law": "lp"}],
        }
        | changes
    )
    return expand(study)


def test_only_the_runs_the_file_lacks_run(tmp_path: Path) -> None:
    path = tmp_path / "results.parquet"
    first, second = runs()
    with LocalPool(1) as pool:
        counts = drive([first], pool, path, "tiny")
        assert (counts["runs"], counts["already_there"], counts["ran"]) == (1, 0, 1)
        (kept,) = results.read(path)
        moved = dataclasses.replace(first, index=5)  # the same run, placed after another now
        counts = drive([second, moved], pool, path, "tiny")
    assert (counts["runs"], counts["already_there"], counts["ran"], counts["failed"]) == (
        2,
        1,
        1,
        0,
    )
    assert counts["workers"] == 1 and counts["runs_per_minute"] > 0
    rows = {row["key"]: row for row in results.read(path)}
    assert set(rows) == {first.key, second.key}
    assert rows[first.key]["index"] == 5 and rows[first.key]["wall_s"] == kept["wall_s"]
    assert rows[second.key]["status"] == "ok" and rows[second.key]["tries"] == 1
    with LocalPool(1) as pool:
        again = drive([second, moved], pool, path, "tiny")
    assert (again["ran"], again["runs_per_minute"]) == (0, None)


def test_a_failed_run_is_tried_once_more_and_its_row_says_why(tmp_path: Path) -> None:
    path = tmp_path / "results.parquet"
    with LocalPool(2) as pool:
        counts = drive(runs(time_limit_s=0.001), pool, path, "hung")
    assert (counts["ran"], counts["failed"]) == (2, 2)
    for row in results.read(path):
        assert (row["status"], row["tries"]) == ("failed", 2)
        assert row["reason"].startswith("hung: no answer within its time limit")
