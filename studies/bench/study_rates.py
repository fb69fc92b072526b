"""Runs per minute of a kinematic and of a whole-loop study, on the local pool and on a local
Dask cluster of as many workers, and the study engine's cost per run.

Run as ``python -m studies.bench.study_rates [--goals N] [--experiments M] [--empty K]
[--workers 1,2] [--json]``. Each study is driven as ``parsimony study`` drives it
(``studies.study.drive``) into a results file of its own in a temporary directory: a kinematic
study of N goals ahead (the default LP, seed 2), a whole-loop study of M pose experiments
(seeds 0..M-1, lockstep, vision and the recorder on), and K runs that do nothing (each still
forked, answered and reaped: the engine's cost alone), on the local pool of W workers and on a
Dask scheduler with W workers started on 127.0.0.1 (``cluster.local_cluster``). Printed per
study and runner: runs per minute, the median run's own wall time (fork to reap), and the
engine's cost per run: the time a worker slot spends per run besides the run's own
(W x elapsed / runs - mean wall), after a warm-up (each worker's first run imports the
engine). The machine's load average is printed with them.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from outputs.stdout import emit, json_text, result_only_stdout, table
from studies.study import results, runs
from studies.study.cluster import DaskCluster, local_cluster
from studies.study.drive import drive
from studies.study.local import LocalPool
from studies.study.schema import Study
from studies.study.sweep import expand


def studies(goals: int, experiments: int, empty: int) -> dict[str, Study]:
    """The studies timed, by name."""
    lp = [{"law": "lp"}]
    kinematic = {"families": ["ahead"], "goals": goals, "seeds": [2], "laws": lp}
    return {
        "kinematic": Study.model_validate({"name": "kinematic"} | kinematic),
        "whole loop": Study.model_validate(
            {"name": "whole-loop", "loop": "simulated", "experiments": ["pose"]}
            | {"seeds": list(range(experiments)), "laws": lp}
        ),
        "nothing": Study.model_validate({"name": "nothing"} | kinematic | {"goals": empty}),
    }


def nothing(run: object) -> dict[str, Any]:
    """A run that does nothing: what ``runs.perform`` becomes for the ``nothing`` study."""
    return {}


def doing(empty: bool) -> Callable[[], None]:
    """A function making every run do nothing (``empty``) or its own, in the process it runs in
    (a Dask worker's too: it keeps the runs' own ``perform`` there, as found the first time)."""

    def set_it() -> None:
        own = runs.__dict__.setdefault("own_perform", runs.perform)
        runs.perform = nothing if empty else own

    return set_it


def use(runner: LocalPool | DaskCluster, empty: bool) -> None:
    """Every run of ``runner`` (and of this process) from now on doing nothing, or its own."""
    doing(empty)()
    if isinstance(runner, DaskCluster):
        runner.on_each_worker(doing(empty))


def timed(study: Study, runner: Any, directory: Path) -> dict[str, Any]:
    """``study`` driven on ``runner`` from nothing: runs per minute, the median run's wall
    time and the engine's cost per run (s)."""
    path = directory / f"{study.name}-{runner.__class__.__name__}-{runner.workers}.parquet"
    planned = expand(study, Path("."), path.with_suffix(""))
    started = time.monotonic()
    counts = drive(planned, runner, path, f"{study.name}, {runner.workers}")
    elapsed = time.monotonic() - started
    walls = [row["wall_s"] for row in results.read(path)]
    return {
        "runs": counts["runs"],
        "failed": counts["failed"],
        "runs_per_minute": round(60.0 * counts["runs"] / elapsed, 1),
        "run_wall_s_median": round(statistics.median(walls), 3),
        "engine_s_per_run": round(
            runner.workers * elapsed / counts["runs"] - statistics.mean(walls), 4
        ),
    }


def measure(timed_studies: dict[str, Study], workers: list[int]) -> list[dict[str, Any]]:
    """Every study on the local pool and on a local Dask cluster of each count of workers."""
    rows = []
    with tempfile.TemporaryDirectory() as name:
        for count in workers:
            for runner_name in RUNNERS:
                with runner_of(runner_name, count, Path(name)) as runner:
                    use(runner, True)
                    warm = timed_studies["nothing"].model_copy(update={"name": "warm-up"})
                    timed(warm, runner, Path(name))  # each worker's imports, not timed
                    for study_name, study in timed_studies.items():
                        use(runner, study_name == "nothing")
                        found = timed(study, runner, Path(name))
                        progress(f"{study_name} on {runner_name} of {count}: {found}")
                        load = round(os.getloadavg()[0], 1)
                        rows.append(
                            {"study": study_name, "runner": runner_name, "workers": count}
                            | found
                            | {"load_average": load}
                        )
                doing(False)()
    return rows


RUNNERS = ("local pool", "Dask, local")


@contextlib.contextmanager
def runner_of(name: str, workers: int, directory: Path) -> Iterator[LocalPool | DaskCluster]:
    """The runner ``name`` of ``workers`` workers: the local pool, or a Dask cluster started
    on 127.0.0.1 for it (stopped on leaving)."""
    if name == "local pool":
        with LocalPool(workers) as pool:
            yield pool
        return
    folder = directory / f"dask-{workers}"
    folder.mkdir()
    with local_cluster(workers, folder) as address, DaskCluster(address) as cluster:
        yield cluster


def progress(what: str) -> None:
    print(f"study_rates: {what}", file=sys.stderr, flush=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--goals", type=int, default=24, help="kinematic runs (default 24)")
    parser.add_argument("--experiments", type=int, default=4, help="whole-loop runs (default 4)")
    parser.add_argument("--empty", type=int, default=40, help="runs doing nothing (default 40)")
    parser.add_argument("--workers", default="1,2", help="worker counts (default 1,2)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = parser.parse_args(argv)
    try:
        workers = [int(w) for w in args.workers.split(",")]
    except ValueError:
        workers = []
    if min(args.goals, args.experiments, args.empty, *workers, 0 if not workers else 1) < 1:
        print(
            "studies.bench.study_rates: --goals, --experiments, --empty and each of --workers "
            "must be 1 or more",
            file=sys.stderr,
        )
        return 2
    rows = measure(studies(args.goals, args.experiments, args.empty), workers)
    if args.json:
        emit(json_text({"bench": "study_rates", "cpus": os.cpu_count(), "rows": rows}))
    else:
        emit(table(rows, floatfmt=".4g"))
    return 0


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
