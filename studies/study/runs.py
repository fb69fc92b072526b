"""What one run of a sweep does, in the process it is given: a kinematic attempt at one goal
(``studies.goal_sets.attempt``) or one experiment on the whole simulated loop
(``studies.experiment.run_experiment``), as a row of figures; and the checks that refuse a
sweep naming a family, an experiment, a law or a gain nobody has, before anything runs."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np

from outputs.stdout import json_text
from profiles.profile import ProfileError
from sim2d.scenarios import NAMES
from studies.experiment import PROFILES, Options, law_overrides, run_experiment
from studies.goal_families import FAMILIES, OBSTACLE_FAMILIES, goals, obstacle_goals
from studies.goal_sets import LAWS, SUPERVISED, Attempt, attempt
from studies.study.schema import StudyError
from studies.study.sweep import Run
from wbc.laws.kinematic_run import ControlEffort
from wbc.laws.law_output import Law
from wbc.robot import MobileManipulator

EXPERIMENT_FIGURES = (
    "converged",
    "contacts",
    "joint_limit_violations",
    "real_time_factor",
    "wall_time_s",
    "sim_time_s",
)
"""The scalars of an experiment's report that its row keeps as columns (all of it in
``report``)."""


def law(name: str, gains: dict[str, Any], robot: MobileManipulator) -> Law:
    """Law ``name`` of ``LAWS`` with ``gains`` changed (TypeError or ValueError naming a gain
    it has not, or a value it refuses)."""
    made = LAWS[name](robot)
    if not gains:
        return made
    return type(made)(robot, dataclasses.replace(made.params, **gains))  # type: ignore[attr-defined]


def check_place(loop: str, place: str) -> None:
    """``StudyError`` unless ``place`` is a goal family (kinematic) or an experiment."""
    known = [*FAMILIES, *OBSTACLE_FAMILIES] if loop == "kinematic" else list(NAMES)
    if place not in known:
        what = "goal family" if loop == "kinematic" else "experiment"
        raise StudyError(f"no {what} {place!r}; known: {'; '.join(known)}")


def check_law(loop: str, name: str, gains: dict[str, Any], place: str, robot_file: Path) -> None:
    """``StudyError`` unless law ``name`` exists for ``loop`` and takes ``gains``."""
    known = list(LAWS) if loop == "kinematic" else list(PROFILES)
    if name not in known:
        raise StudyError(f"no {loop} law {name!r}; known: {'; '.join(known)}")
    try:
        if loop == "kinematic":
            law(name, gains, MobileManipulator.from_yaml(robot_file))
        else:
            law_overrides(Options(name=place, controller=name, gains=gains))
    except (TypeError, ValueError, ProfileError) as error:
        raise StudyError(f"law {name!r} with gains {gains}: {error}") from None


def perform(run: Run) -> dict[str, Any]:
    """The figures of ``run`` (its columns beside its parameters)."""
    if run.loop == "kinematic":
        return kinematic(run)
    return simulated(run)


def kinematic(run: Run) -> dict[str, Any]:
    """One attempt at the run's goal: the goal drawn ``goal``-th from the run's seed, as the
    family draws its sets (so a run is the same as in a set drawn whole)."""
    p = run.parameters
    robot = MobileManipulator.from_yaml(run.robot_file)
    obstacles: tuple = ()
    if p["family"] in OBSTACLE_FAMILIES:
        drawn = obstacle_goals(OBSTACLE_FAMILIES[p["family"]], p["goal"] + 1, robot, p["seed"])
        start, goal, circle = drawn[p["goal"]]
        obstacles = (circle,)
    else:
        start, goal = goals(FAMILIES[p["family"]], p["goal"] + 1, robot, p["seed"])[p["goal"]]
    found = attempt(
        law(p["law_name"], json.loads(p["gains"]), robot),
        robot,
        start,
        goal,
        supervised=p["law_name"] == SUPERVISED,
        position=p["task"] == "position",
        obstacles=obstacles,
    )
    row = dataclasses.asdict(found)
    row["last"] = found.last.tolist() if found.last is not None else None
    return row | {
        "start": start.tolist(),
        "goal_q": goal.tolist(),
        "obstacles": [list(dataclasses.astuple(c)) for c in obstacles],
    }


def attempt_of(row: dict[str, Any]) -> Attempt:
    """The ``Attempt`` a kinematic row holds (``kinematic``'s inverse)."""
    values = {}
    for field in dataclasses.fields(Attempt):
        value = row[field.name]
        if field.name in ("effort", "effort_from_rest") and value is not None:
            value = ControlEffort(**value)
        elif field.name == "last" and value is not None:
            value = np.asarray(value)
        elif isinstance(value, list | np.ndarray):
            value = tuple(value)
        values[field.name] = value
    return Attempt(**values)


def simulated(run: Run) -> dict[str, Any]:
    """One experiment on the whole simulated loop, its directory ``out`` of the run; its own
    namespace (this process's id) and router port, whichever machine it runs on."""
    p = run.parameters
    options = Options(
        name=p["experiment"],
        controller=p["law_name"],
        seed=p["seed"],
        out=Path(run.out),
        robot=Path(run.robot_file),
        gains=json.loads(p["gains"]),
    )
    report = run_experiment(options)
    return {name: report.get(name) for name in EXPERIMENT_FIGURES} | {"report": json_text(report)}
