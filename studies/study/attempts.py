"""A kinematic sweep run on the local pool (``drive``: retries, progress on stderr) and handed
back as ``studies.goal_sets.Attempt`` lists, for a benchmark that prints its own tables."""

from __future__ import annotations

import tempfile
from pathlib import Path

from studies.goal_sets import Attempt
from studies.study import results
from studies.study.drive import drive
from studies.study.execute import OK
from studies.study.local import LocalPool
from studies.study.runs import attempt_of
from studies.study.schema import Study
from studies.study.sweep import expand


def sweep_attempts(study: Study, workers: int | None = None) -> dict[tuple, list[Attempt]]:
    """Each (family, task, seed, law label)'s attempts in goal order; RuntimeError naming a
    run that failed twice."""
    runs = expand(study)
    with tempfile.TemporaryDirectory() as directory, LocalPool(workers) as pool:
        path = Path(directory) / "results.parquet"
        drive(runs, pool, path, study.name)
        rows = results.read(path)
    found: dict[tuple, list[Attempt]] = {}
    for row in rows:
        if row["status"] != OK:
            raise RuntimeError(f"run {row['key']} failed: {row['reason']}")
        key = (row["family"], row["task"], row["seed"], row["law"])
        found.setdefault(key, []).append(attempt_of(row))
    return found
