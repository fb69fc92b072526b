"""A result of `parsimony reproduce` (a row: the dissertation's value beside ours) and the
tables it prints."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from outputs.stdout import table


@dataclass(frozen=True)
class Row:
    """One result: the dissertation's value, ours, and which way the comparison should go.
    ``key`` names it for the golden results of the tests; ``laws`` are the labels of the laws
    whose runs of ``experiment`` it reports (what each ran: ``studies.reproduce.laws``);
    ``timed`` marks a figure of the wall clock, which depends on the machine."""

    key: str
    section: str
    result: str
    dissertation: Any
    ours: Any
    direction: str = ""
    experiment: str = ""
    laws: tuple[str, ...] = ()
    timed: bool = False


def shown(value: Any) -> str:
    """A value as the table prints it: numbers to 4 significant digits."""
    if isinstance(value, list):
        return "[" + ", ".join(shown(v) for v in value) + "]"
    if isinstance(value, dict):
        return ", ".join(f"{k} {shown(v)}" for k, v in value.items())
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def format_rows(rows: list[Row]) -> str:
    return table(
        [(r.section, r.result, shown(r.dissertation), shown(r.ours), r.direction) for r in rows],
        ("section", "result", "dissertation", "ours", "should be"),
        disable_numparse=True,
    )


def format_laws(laws: list[dict[str, str]]) -> str:
    """Which law each label of each experiment ran: its rows and its terms."""
    return table(
        [(law["experiment"], law["label"], law["ran"]) for law in laws],
        ("experiment", "law", "what it ran"),
        disable_numparse=True,
    )
