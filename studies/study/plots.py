"""A study's plots (PNG), from its results: a point per group of runs, one figure against
others, a line per law (or another parameter: a colour each, wider as they come, as they may
overlap) and a panel per task (or another)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from studies.study.report import figures_of, groups, robots
from studies.study.schema import Plot, Study
from studies.study.sweep import Run

STYLES = ("-", ":", "--", "-.")
"""The line of each figure of ``y``."""


def draw(study: Study, plot: Plot, runs: list[Run], rows: list[dict[str, Any]]) -> Path:
    """``plot`` of ``study`` over ``rows``, written to its file."""
    figures, loaded = figures_of(study), robots(runs)
    points: dict[Any, dict[Any, list[tuple[float, list[float]]]]] = {}
    for group in groups(rows, [plot.panels, plot.lines, *plot.by]).values():
        robot = loaded[group[0]["robot"]]
        values: dict[str, Any] = {}
        for name in (plot.x, *plot.y):
            values |= figures[name](group, robot)
        x, *ys = values.values()
        line = points.setdefault(group[0][plot.panels], {}).setdefault(group[0][plot.lines], [])
        line.append((x, ys))
    fig = Figure(figsize=(4.5 * len(points) + 1.5, 3.4), layout="constrained")
    axes = None
    for index, (panel, lines) in enumerate(points.items()):
        axes = fig.add_subplot(1, len(points), index + 1)
        xs = sorted({x for line in lines.values() for x, _ in line})
        if plot.diagonal:
            axes.plot(xs, xs, color="0.7", linewidth=3, label=plot.diagonal)
        for number, (label, line) in enumerate(lines.items()):
            line.sort(key=lambda point: point[0])
            look = {"color": f"C{number}", "linewidth": 1.5 * (number + 1), "alpha": 0.8}
            look["zorder"] = len(lines) - number  # each line over the wider ones after it
            for part, style in zip(plot.y, STYLES, strict=False):
                ys = [y[plot.y.index(part)] for _, y in line]
                xs_line = [x for x, _ in line]
                axes.plot(xs_line, ys, style, marker="o", label=f"{label}, {part}", **look)
        axes.set_title(f"{plot.panels} {panel}")
        axes.set_xlabel(plot.x)
        axes.set_ylabel(", ".join(plot.y))
        axes.set_xticks(xs)
        axes.grid(alpha=0.3)
    if axes is not None:
        fig.legend(*axes.get_legend_handles_labels(), fontsize=7, loc="outside right center")
    Path(plot.file).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(plot.file, dpi=72)
    return Path(plot.file)
