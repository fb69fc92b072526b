"""`parsimony bench`'s goal sets: every family and law of ``studies.goal_sets.LAWS`` run as
kinematic studies on the local pool (``studies.study.attempts``), and their shares, parsimony
and misses by reason."""

from __future__ import annotations

from pathlib import Path

from studies.goal_families import FAMILIES, GOAL_SEED, OBSTACLE_FAMILIES
from studies.goal_sets import (
    LAWS,
    POSITION_LAWS,
    SUPERVISED,
    failures,
    not_reached,
    parsimony,
    planning,
    shares,
)
from studies.study.attempts import sweep_attempts
from studies.study.schema import Study
from wbc.robot import MobileManipulator


def goal_report(robot_file: Path, count: int, processes: int = 2) -> dict:
    """For every family and law of ``LAWS``: the shares reached, the parsimony of u and
    the goals not reached by reason, for the pose task and, with the laws of POSITION_LAWS,
    for the position task of the same goals; and the LP under the supervisor on the goals of
    OBSTACLE_FAMILIES with the contacts and planning times. The runs are studies on the local
    pool of ``processes`` (``studies.study.attempts``)."""
    robot = MobileManipulator.from_yaml(robot_file)
    sweeps = [
        (task, [*FAMILIES], [GOAL_SEED], names)
        for task, names in (("pose", tuple(LAWS)), ("position", POSITION_LAWS))
    ]
    sweeps += [("pose", [f.name], [f.seed], (SUPERVISED,)) for f in OBSTACLE_FAMILIES.values()]
    report: dict = {}
    for task, families, seeds, names in sweeps:
        study = Study.model_validate(
            {"name": f"bench-{task}", "robots": [str(robot_file)], "families": families}
            | {"task": task, "goals": count, "seeds": seeds}
            | {"laws": [{"law": name} for name in names]}
        )
        found = sweep_attempts(study, processes)
        for family in families:
            rows = {}
            for name in names:
                attempts = found[(family, task, seeds[0], name)]
                rows[name] = {
                    **shares(attempts),
                    **parsimony(attempts, robot.dof),
                    **not_reached(attempts),
                }
                if family in OBSTACLE_FAMILIES:
                    rows[name].update(failures(attempts))
                if name == SUPERVISED:
                    rows[name].update(planning(attempts))
            report[f"{family} {task}"] = {"goals": count, "laws": rows}
    order = [f"{family} {task}" for family in FAMILIES for task in ("pose", "position")]
    return {key: report[key] for key in order} | report
