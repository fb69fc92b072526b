"""The local pool: as many runs at once as the machine has cores (or ``workers``), each in a
child process forked for it (``execute``)."""

from __future__ import annotations

import os
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor, as_completed
from typing import Any

from studies.study.execute import execute, stop_all
from studies.study.sweep import Run


class LocalPool:
    """Runs on this machine; a thread per worker waits on its run's process."""

    def __init__(self, workers: int | None = None) -> None:
        self.workers = workers or os.cpu_count() or 1

    def __enter__(self) -> LocalPool:
        self._threads = ThreadPoolExecutor(self.workers, thread_name_prefix="study")
        return self

    def __exit__(self, kind: type | None, *exc: object) -> None:
        """Waits for the runs under way, or, when the study was stopped, kills them."""
        if kind is not None:
            stop_all()
        self._threads.shutdown(wait=True, cancel_futures=True)

    def outcomes(self, runs: list[Run]) -> Iterator[tuple[Run, dict[str, Any]]]:
        """Each run with its outcome (``execute``), in the order they finish."""
        futures = {self._threads.submit(execute, run): run for run in runs}
        for future in as_completed(futures):
            yield futures[future], future.result()
