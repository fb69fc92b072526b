"""`parsimony reproduce`: every result of chapter 6, the dissertation's beside ours.

The set-ups of chapter 6 run kinematically (q += u dt at 50 Hz, on the robot of deploy/robots,
from ``wbc.geometry.scenarios.HOME``) with the dissertation's gains (``runs``): 6.2.1 (pose), 6.2.2
(position), the joint limit of figure 6.10, 6.2.3 (obstacle), table 6.1, and section 6.3 as
the dissertation ran it (``efficiency``). Every law is named by a label, and the command says
what each label ran, its rows and terms read from the law itself (``laws``). Each row gives
what the dissertation reports (``dissertation``), what this run measures (``measures``) and the
direction the comparison should take by the dissertation's text; the command makes no
judgement. ``write_figures`` draws the runs with the report's own figures. ``loop`` runs the
set-ups of 6.2 on the whole simulated loop and gives the same rows of each recording
(``--loop``).
"""

from __future__ import annotations

from collections.abc import Callable

from studies.reproduce.dissertation import NOTES, TABLE_6_1
from studies.reproduce.efficiency import TRIALS, section_6_3
from studies.reproduce.figures import write_figures
from studies.reproduce.future_work import input_change_rows, qp_rows
from studies.reproduce.rows import (
    effort_rows,
    joint_limit_rows,
    obstacle_rows,
    step_time_rows,
    task_rows,
)
from studies.reproduce.runs import NAMES, Experiment, experiments
from studies.reproduce.table import Row, format_laws, format_rows
from wbc.robot import MobileManipulator

__all__ = [
    "NAMES",
    "NOTES",
    "TABLE_6_1",
    "TRIALS",
    "Row",
    "format_laws",
    "format_rows",
    "reproduce",
    "write_figures",
]


def reproduce(
    robot: MobileManipulator, trials: int = TRIALS, names: tuple[str, ...] = NAMES
) -> tuple[list[Row], list[dict[str, str]], dict[str, Experiment]]:
    """The rows, what each law ran, and the experiments they come from: the set-ups
    ``names`` and, with all of them, section 6.3. The timed tests of 6.3 run first, before
    thousands of runs' outputs load the garbage collector."""
    timing, ran = section_6_3(robot, trials) if set(names) == set(NAMES) else ([], [])
    found = experiments(robot, names)

    def each(make: Callable[[Experiment], list[Row]], *wanted: str) -> list[Row]:
        return [row for name in wanted if name in found for row in make(found[name])]

    rows = [
        *each(lambda e: task_rows(robot, e), "pose"),
        *each(lambda e: joint_limit_rows(robot, e), "joint_limit"),
        *each(lambda e: task_rows(robot, e), "position"),
        *each(effort_rows, "pose", "position"),
        *each(lambda e: obstacle_rows(robot, e), "obstacle"),
        *step_time_rows(found),
        *timing,
        *each(qp_rows, "pose", "position"),
        *each(input_change_rows, "pose", "position"),
    ]
    laws = [
        {"experiment": name, "label": label, "ran": text}
        for name, experiment in found.items()
        for label, text in experiment.laws.items()
    ]
    return rows, laws + ran, found
