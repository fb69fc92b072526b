"""A Dask cluster (``--address tcp://HOST:PORT`` of a ``dask scheduler``): each run a task,
which forks the run's process on whichever worker it lands (``execute``). A worker lost while
it held a run is the run's failure, with that reason; the scheduler hands its other runs on.
``local_cluster`` starts one on this machine (the tests', the benchmark's)."""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from distributed import Client, as_completed

from studies.study.execute import execute, failed
from studies.study.places import check_law, kind
from studies.study.sweep import Run

ROOT = Path(__file__).resolve().parents[2]
"""The checkout the workers of ``local_cluster`` run from."""


class DaskCluster:
    """Runs on the Dask cluster whose scheduler listens at ``address``."""

    def __init__(self, address: str) -> None:
        self.address = address

    def __enter__(self) -> DaskCluster:
        self._client = Client(self.address, set_as_default=False, timeout="30s")
        self.workers = len(self._client.scheduler_info(n_workers=-1)["workers"])
        return self

    def __exit__(self, *exc: object) -> None:
        self._client.close()

    def on_each_worker(self, function: Callable[[], object]) -> None:
        """Call ``function`` in every worker's process."""
        self._client.run(function)

    def outcomes(self, runs: list[Run]) -> Iterator[tuple[Run, dict[str, Any]]]:
        """Each run with its outcome (``execute``), in the order they finish."""
        self._client.run(warm, sorted({law_of(run) for run in runs}))
        futures = {self._client.submit(execute, run, pure=False): run for run in runs}
        for future in as_completed(futures, loop=self._client.loop):
            run = futures.pop(future)
            try:
                yield run, future.result()
            except Exception as error:  # the worker went away, or the task never came back
                yield run, failed(f"lost its worker: {type(error).__name__}: {error}", 0.0)


@contextlib.contextmanager
def local_cluster(workers: int, directory: Path, timeout_s: float = 120.0) -> Iterator[str]:
    """A Dask scheduler and ``workers`` workers (one thread each, no nanny) on 127.0.0.1, each a
    process of its own started from this checkout: the scheduler's address. They are stopped
    on leaving."""
    dask = Path(sys.executable).parent / "dask"
    file = directory / "scheduler.json"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    quiet = {"cwd": ROOT, "env": env, "stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    common = ["--host", "127.0.0.1", "--no-dashboard"]
    scheduler = [dask, "scheduler", *common, "--port", "0", "--scheduler-file", file]
    processes = [subprocess.Popen(scheduler, **quiet)]
    try:
        deadline = time.monotonic() + timeout_s
        while not (address := _address(file)):  # written once the scheduler listens
            if processes[0].poll() is not None or time.monotonic() > deadline:
                raise RuntimeError("the Dask scheduler did not start")
            time.sleep(0.1)
        worker = [dask, "worker", address, *common, "--nthreads", "1", "--no-nanny"]
        processes += [subprocess.Popen(worker, **quiet) for _ in range(workers)]
        with Client(address, timeout=f"{timeout_s:g}s") as client:
            client.wait_for_workers(workers, timeout=timeout_s)
        yield address
    finally:
        for process in reversed(processes):
            process.terminate()
        for process in processes:
            try:
                process.wait(timeout=5)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


def _address(file: Path) -> str:
    """The scheduler's address in its file; empty while the file is not there or not whole."""
    try:
        return json.loads(file.read_text())["address"]
    except (OSError, ValueError, KeyError):
        return ""


def law_of(run: Run) -> tuple[str, str, str, str, str]:
    """What ``warm`` makes for ``run``: its loop, place, law, gains and robot."""
    p = run.parameters
    place = p.get("family") or p["experiment"]
    return run.loop, place, p["law_name"], p["gains"], run.robot_file


def warm(laws: list[tuple[str, str, str, str, str]]) -> None:
    """Load each robot and make each law of ``laws`` (``law_of``) once in this process, as the
    local pool's process does when it checks a sweep: a run forked from a worker that has not
    is 3 to 4 times slower (a kinematic run of 0.25 s took 0.8-1.0 s)."""
    for loop, place, name, gains, robot_file in laws:
        check_law(kind(loop, place), name, json.loads(gains), place, Path(robot_file))
