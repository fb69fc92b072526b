"""A study's report: its tables (Markdown) from its results file, each naming the study and
the command that made it, and its plots (``plots``); and the block of its docs page (``page``)
between the study's markers, replaced by the tables."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tabulate import tabulate

from outputs.stdout import finite
from studies.study import places
from studies.study.figures import COMPARED, KINEMATIC, SETUP, SIMULATED, ZOO, Figure
from studies.study.schema import Study, StudyError, Table
from studies.study.sweep import PARAMETERS, Run, laws
from wbc.robot import MobileManipulator

FIGURES: dict[str, dict[str, Figure]] = {
    places.GOALS: KINEMATIC,
    places.ZOO: ZOO,
    places.SETUP: SETUP,
    places.SIMULATED: SETUP | SIMULATED,
}
"""The figures a table may name, by the kind of the study's places."""


def figures_of(study: Study) -> dict[str, Figure]:
    """The figures every loop of ``study`` has, for the kind of its places."""
    place = (study.families or study.experiments)[0]
    each = [FIGURES[places.kind(loop, place)] for loop in study.loops]
    return {name: figure for name, figure in each[0].items() if all(name in f for f in each)}


def values(study: Study) -> dict[str, set]:
    """The values each parameter of ``study``'s runs takes."""
    return {
        "loop": set(study.loops),
        "robot": {Path(robot).stem for robot in study.robots},
        "family": set(study.families),
        "experiment": set(study.experiments),
        "task": set(study.tasks) if study.families else {None},
        "seed": {seed for loop in study.loops for seed in study.seeds_of(loop)},
        "goal": set(range(study.goals)) if study.families else {None},
        "law": {label for spec in study.laws for label, _ in laws(spec)},
    }


def check_tables(study: Study) -> None:
    """``StudyError`` naming a table's or a plot's unknown parameter, value or figure."""
    known = figures_of(study)
    taken = values(study)
    for table in study.tables:
        for name in [*table.by, *table.where]:
            if name not in PARAMETERS:
                raise StudyError(f"table {table.title!r}: no parameter {name!r}; {PARAMETERS}")
        for name, wanted in table.where.items():
            if unknown := [value for value in wanted if value not in taken[name]]:
                raise StudyError(f"table {table.title!r}: no {name} {unknown[0]!r} in the study")
        for name in table.figures:
            if name in COMPARED and table.against is None:
                raise StudyError(f"table {table.title!r}: {name!r} needs 'against: LAW'")
            if name not in known and name not in COMPARED:
                raise StudyError(
                    f"table {table.title!r}: no figure {name!r}; known: {'; '.join(known)}"
                )
    for plot in study.plots:
        for name in (plot.lines, plot.panels, *plot.by):
            if name not in PARAMETERS:
                raise StudyError(f"plot {plot.file}: no parameter {name!r}; {PARAMETERS}")
        for name in (plot.x, *plot.y):
            if name not in known:
                raise StudyError(f"plot {plot.file}: no figure {name!r}; known: {'; '.join(known)}")


def robots(runs: list[Run]) -> dict[str, MobileManipulator]:
    """The runs' robots by name."""
    files = {run.parameters["robot"]: run.robot_file for run in runs}
    return {name: MobileManipulator.from_yaml(path) for name, path in files.items()}


def counted(table: Table, row: dict[str, Any]) -> bool:
    """Whether ``table`` counts ``row`` (its ``seeds`` and ``where``)."""
    if table.seeds and row["seed"] not in table.seeds:
        return False
    return all(row[name] in wanted for name, wanted in table.where.items())


def groups(rows: list[dict[str, Any]], by: list[str]) -> dict[tuple, list]:
    """``rows`` grouped by the values of ``by``, in the runs' order."""
    found: dict[tuple, list[dict[str, Any]]] = {}
    for row in sorted(rows, key=lambda r: r["index"]):
        found.setdefault(tuple(row[name] for name in by), []).append(row)
    return found


def table_lines(
    study: Study, table: Table, rows: list[dict[str, Any]], loaded: dict[str, MobileManipulator]
) -> list[dict[str, Any]]:
    """A line per group of ``table``: its parameters and figures."""
    figures = figures_of(study)
    found = groups([row for row in rows if counted(table, row)], table.by)
    lines = []
    for values, group in found.items():
        robot = loaded[group[0]["robot"]]
        line: dict[str, Any] = dict(zip(table.by, values, strict=True))
        for name in table.figures:
            if name in COMPARED:
                reference = [r for r in rows if r["law"] == table.against]
                line |= COMPARED[name](group, reference, robot)
            else:
                line |= figures[name](group, robot)
        lines.append(finite(line))  # a median of no step is blank, not nan
    return lines


def pages(study: Study) -> list[Path]:
    """The docs pages ``study``'s tables go in, in the tables' order."""
    found = [table.page or study.page for table in study.tables] or [study.page]
    return list(dict.fromkeys(page for page in found if page is not None))


def markdown(
    study: Study, file: str, runs: list[Run], rows: list[dict[str, Any]], page: Path | None = None
) -> str:
    """The tables of ``study`` over ``rows`` (the runs' robots from ``runs``): every table, or
    those that go in ``page``."""
    loaded = robots(runs)
    done = sum(row["status"] == "ok" for row in rows)
    parts = [
        f"Made by `parsimony study {file} --report` from its results: {len(rows)} of "
        f"{len(runs)} runs, {done} of them run to the end."
    ]
    for table in study.tables:
        if page is not None and (table.page or study.page) != page:
            continue
        lines = table_lines(study, table, rows, loaded)
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
