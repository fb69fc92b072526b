"""`parsimony reproduce`: every result of chapter 6, the dissertation's beside ours.

The set-ups of chapter 6 run kinematically (q += u dt at 50 Hz, on the robot of deploy/robots,
from ``wbc.scenarios.HOME``) with the dissertation's gains (``runs``): 6.2.1 (pose), 6.2.2
(position), the joint limit of figure 6.10, 6.2.3 (obstacle), table 6.1, and section 6.3 as
the dissertation ran it (``efficiency``). Every law is named by a label, and the command says
what each label ran, its rows and terms read from the law itself (``laws``). Each row gives
what the dissertation reports (``dissertation``), what this run measures (``measures``) and the
direction the comparison should take by the dissertation's text; the command makes no
judgement. ``write_figures`` draws the runs with the report's own figures.
"""

from __future__ import annotations

from parsimony.reproduce.dissertation import NOTES, TABLE_6_1
from parsimony.reproduce.efficiency import TRIALS, section_6_3
from parsimony.reproduce.figures import write_figures
from parsimony.reproduce.future_work import input_change_rows, qp_rows
from parsimony.reproduce.rows import (
    effort_rows,
    joint_limit_rows,
    obstacle_rows,
    step_time_rows,
    task_rows,
)
from parsimony.reproduce.runs import Experiment, experiments
from parsimony.reproduce.table import Row, format_laws, format_rows
from wbc.robot import MobileManipulator

__all__ = ["NOTES", "TABLE_6_1", "TRIALS", "Row", "format_laws", "format_rows", "reproduce",
           "write_figures"]  # fmt: skip


def reproduce(robot: MobileManipulator, trials: int = TRIALS
              ) -> tuple[list[Row], list[dict[str, str]], dict[str, Experiment]]:  # fmt: skip
    """The rows, what each law ran, and the experiments they come from. The timed tests of
    6.3 run first, before thousands of runs' outputs load the garbage collector."""
    timing, ran = section_6_3(robot, trials)
    found = experiments(robot)
    pose, position = found["pose"], found["position"]
    rows = [*task_rows(robot, pose), *joint_limit_rows(robot, found["joint_limit"]),
            *task_rows(robot, position), *effort_rows(pose), *effort_rows(position),
            *obstacle_rows(robot, found["obstacle"]), *step_time_rows(found), *timing,
            *qp_rows(pose), *qp_rows(position), *input_change_rows(pose),
            *input_change_rows(position)]  # fmt: skip
    laws = [{"experiment": name, "label": label, "ran": text}
            for name, experiment in found.items()
            for label, text in experiment.laws.items()]  # fmt: skip
    return rows, laws + ran, found
