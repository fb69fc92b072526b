"""A study driven to its results file: the runs it lacks, on a runner (``local``,
``cluster``), each failed run retried once after the others, a progress bar on stderr, and the
rows saved as they come (every few seconds, and whatever stops the study)."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any, Protocol

from tqdm import tqdm

from studies.study import results
from studies.study.execute import OK
from studies.study.sweep import Run

SAVE_S = 5.0
"""How often (s) the results file is rewritten while runs come in."""


class Runner(Protocol):
    workers: int

    def outcomes(self, runs: list[Run]) -> Iterator[tuple[Run, dict[str, Any]]]: ...


def row(run: Run, outcome: dict[str, Any], tries: int) -> dict[str, Any]:
    """The results' row of ``run``."""
    return {
        "index": run.index,
        "key": run.key,
        **run.parameters,
        "status": outcome["status"],
        "reason": outcome["reason"],
        "tries": tries,
        "wall_s": outcome["wall_s"],
        **(outcome["figures"] or {}),
    }


def drive(runs: list[Run], runner: Runner, path: Path, label: str) -> dict[str, Any]:
    """Run what ``path`` lacks of ``runs``; return the counts: runs, already there, ran,
    failed (after their retry), and the runs per minute of this invocation."""
    index = {run.key: run.index for run in runs}
    rows = {
        r["key"]: r | {"index": index[r["key"]]} for r in results.read(path) if r["key"] in index
    }
    todo = [run for run in runs if run.key not in rows]
    bar = tqdm(total=len(runs), initial=len(rows), desc=label, unit="run", file=sys.stderr)
    failed = 0
    saved = time.monotonic()
    started = time.monotonic()
    try:
        retry: list[Run] = []
        for tries, batch in ((1, todo), (2, retry)):
            for run, outcome in runner.outcomes(batch):
                if outcome["status"] != OK and tries == 1:
                    retry.append(run)  # once, after the others
                    bar.set_postfix(failed=failed, to_retry=len(retry))
                    continue
                rows[run.key] = row(run, outcome, tries)
                failed += outcome["status"] != OK
                bar.set_postfix(failed=failed, to_retry=len(retry) if tries == 1 else 0)
                bar.update()
                if time.monotonic() - saved > SAVE_S:
                    results.write(path, list(rows.values()))
                    saved = time.monotonic()
    finally:
        bar.close()
        if rows:
            results.write(path, list(rows.values()))
    minutes = (time.monotonic() - started) / 60.0
    return {
        "runs": len(runs),
        "already_there": len(runs) - len(todo),
        "ran": len(todo),
        "failed": failed,
        "workers": runner.workers,
        "runs_per_minute": round(len(todo) / minutes, 1) if todo and minutes > 0 else None,
    }
