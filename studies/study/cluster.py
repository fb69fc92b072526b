"""A Dask cluster (``--address tcp://HOST:PORT`` of a ``dask scheduler``): each run a task,
which forks the run's process on whichever worker it lands (``execute``). A worker lost while
it held a run is the run's failure, with that reason; the scheduler hands its other runs on."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from distributed import Client, as_completed

from studies.study.execute import execute, failed
from studies.study.sweep import Run


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

    def outcomes(self, runs: list[Run]) -> Iterator[tuple[Run, dict[str, Any]]]:
        """Each run with its outcome (``execute``), in the order they finish."""
        futures = {self._client.submit(execute, run, pure=False): run for run in runs}
        for future in as_completed(futures, loop=self._client.loop):
            run = futures.pop(future)
            try:
                yield run, future.result()
            except Exception as error:  # the worker went away, or the task never came back
                yield run, failed(f"lost its worker: {type(error).__name__}: {error}", 0.0)
