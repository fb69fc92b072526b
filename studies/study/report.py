"""A study's report: its tables (Markdown) from its results file, each naming the study and
the command that made it; and the block of its docs page (``page``) between the study's
markers, replaced by them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tabulate import tabulate

from outputs.stdout import finite
from studies.study.figures import KINEMATIC, SIMULATED
from studies.study.schema import Study, StudyError
from studies.study.sweep import PARAMETERS, Run
from wbc.robot import MobileManipulator


def figures_of(study: Study) -> dict:
    return KINEMATIC if study.loop == "kinematic" else SIMULATED


def check_tables(study: Study) -> None:
    """``StudyError`` naming a table's unknown parameter or figure."""
    known = figures_of(study)
    for table in study.tables:
        for name in table.by:
            if name not in PARAMETERS:
                raise StudyError(f"table {table.title!r}: no parameter {name!r}; {PARAMETERS}")
        for name in table.figures:
            if name not in known:
                raise StudyError(
                    f"table {table.title!r}: no figure {name!r}; known: {'; '.join(known)}"
                )


def markdown(study: Study, file: str, runs: list[Run], rows: list[dict[str, Any]]) -> str:
    """Every table of ``study`` over ``rows`` (the runs' robots from ``runs``)."""
    robots = {run.parameters["robot"]: run.robot_file for run in runs}
    loaded = {name: MobileManipulator.from_yaml(path) for name, path in robots.items()}
    figures = figures_of(study)
    done = sum(row["status"] == "ok" for row in rows)
    parts = [
        f"Made by `parsimony study {file} --report` from its results: {len(rows)} of "
        f"{len(runs)} runs, {done} of them run to the end."
    ]
    for table in study.tables:
        groups: dict[tuple, list[dict[str, Any]]] = {}
        for row in sorted(rows, key=lambda r: r["index"]):
            groups.setdefault(tuple(row[name] for name in table.by), []).append(row)
        lines = []
        for values, group in groups.items():
            line: dict[str, Any] = dict(zip(table.by, values, strict=True))
            for name in table.figures:
                line |= figures[name](group, loaded[group[0]["robot"]])
            lines.append(finite(line))  # a median of no step is blank, not nan
        text = tabulate(lines, headers="keys", tablefmt="pipe", floatfmt=".3g", missingval="")
        parts.append(f"**{table.title}**\n\n{text}")
    return "\n\n".join(parts) + "\n"


def markers(study: Study) -> tuple[str, str]:
    return (
        f"<!-- study {study.name}: made by parsimony study -->",
        f"<!-- end of study {study.name} -->",
    )


def update_page(page: Path, study: Study, text: str) -> bool:
    """Replace the block between the study's markers in ``page`` with ``text``; False when
    the page has no such block."""
    begin, end = markers(study)
    content = page.read_text()
    if begin not in content or end not in content:
        return False
    head, _, rest = content.partition(begin)
    _, _, tail = rest.partition(end)
    page.write_text(f"{head}{begin}\n{text}{end}{tail}")
    return True
