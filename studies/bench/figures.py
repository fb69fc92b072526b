"""The figures a benchmark prints of a sample (its median, p99 and maximum), and its command
line."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Iterable, Sequence

import numpy as np

from outputs.stdout import emit, json_text


def spread(values: Sequence[float], digits: int = 1) -> dict[str, float | int | None]:
    """``{"median", "p99", "max", "n"}`` of ``values``, rounded; None for an empty sample."""
    if not values:
        return {"median": None, "p99": None, "max": None, "n": 0}
    data = np.asarray(values, dtype=float)
    return {
        "median": round(float(np.median(data)), digits),
        "p99": round(float(np.percentile(data, 99)), digits),
        "max": round(float(data.max()), digits),
        "n": int(data.size),
    }


def run_bench(
    doc: str,
    measure: Callable[[int], dict],
    lines: Callable[[dict], Iterable[str]],
    runs: int,
    argv: list[str] | None,
) -> int:
    """The command line of a benchmark of ``--runs`` repetitions: its report as lines of
    figures, or as JSON with ``--json``."""
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=runs, help="repetitions of each figure")
    parser.add_argument("--json", action="store_true", help="print JSON instead of lines")
    args = parser.parse_args(argv)
    report = measure(args.runs)
    for line in [json_text(report)] if args.json else lines(report):
        emit(line)
    return 0
