"""A study's results: a Parquet file, one row per run (its place and key, its parameters, its
status, its reason when it failed, its tries and wall time, its figures), sorted by place, so
the same runs give the same file whatever order they finished in. It is rewritten whole (a
partial file renamed onto it), so an interrupted study leaves the rows it had."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from outputs.files import written_whole

TIMING = ("wall_s", "tries")
"""Columns that tell how a run went on this machine, not what it found."""


def read(path: Path) -> list[dict[str, Any]]:
    """The rows of ``path`` (none when it does not exist yet)."""
    if not Path(path).exists():
        return []
    return pq.read_table(path).to_pylist()


def write(path: Path, rows: list[dict[str, Any]]) -> None:
    """``rows`` into ``path``, sorted by the runs' places."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    names = list(dict.fromkeys(name for row in rows for name in row))  # every row's columns
    ordered = sorted(rows, key=lambda row: row["index"])
    table = pa.Table.from_pylist([{name: row.get(name) for name in names} for row in ordered])
    with written_whole(path) as partial:
        pq.write_table(table, partial)


def findings(row: dict[str, Any]) -> dict[str, Any]:
    """A row without its ``TIMING``: what must be equal wherever the run ran."""
    return {name: value for name, value in row.items() if name not in TIMING}
