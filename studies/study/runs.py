"""What one run of a sweep does, in the process it is given, as a row of figures: a kinematic
attempt at one goal of a family (``studies.goal_sets.attempt``) or of the zoo
(``studies.redundancy.run_one``), an experiment's set-up run kinematically, or one experiment
on the whole simulated loop (``studies.experiment.judged_experiment``). A set-up's run and an
experiment's give the same columns (``SETUP_COLUMNS``), so one loop's table compares with the
other's."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import numpy as np

from analysis.run_end import CONVERGED_ERROR, converged_at, messages, origin_s
from messages.topics import CONTROL_DIAGNOSTICS, SUPERVISOR_STATUS
from outputs.stdout import json_text
from profiles.profile import load_profile
from sim2d.scenarios import scenario
from studies import redundancy
from studies.experiment import PROFILES, TIME_LIMIT_S, Options, judged_experiment
from studies.goal_families import FAMILIES, OBSTACLE_FAMILIES, goals, obstacle_goals
from studies.goal_sets import MOVING_ERROR, SUPERVISED, Attempt, attempt
from studies.study.places import GOALS, SETUP, ZOO, ZOO_FAMILY, kind, law
from studies.study.sweep import Run
from wbc.geometry.obstacles import least_clearance
from wbc.geometry.scenarios import DT
from wbc.laws.kinematic_run import ControlEffort, integrate
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

EXPERIMENT_FIGURES = (
    "converged",
    "contacts",
    "joint_limit_violations",
    "real_time_factor",
    "wall_time_s",
    "sim_time_s",
    "final_error",
    "min_obstacle_clearance_m",
)
"""The scalars of an experiment's report that its row keeps as columns (all of it in
``report``)."""
SETUP_COLUMNS = ("converged", "contacts", "min_obstacle_clearance_m", "final_error")
"""What a run of an experiment's set-up gives, on either loop, beside ``converge_s`` (the
simulated time to ``||e||`` under ``CONVERGED_ERROR`` for good, the time limit when never) and
``nonzero_moving`` (the nonzero entries of u at each step with ``||e|| > MOVING_ERROR``)."""


def perform(run: Run) -> dict[str, Any]:
    """The figures of ``run`` (its columns beside its parameters)."""
    place = run.parameters.get("family") or run.parameters["experiment"]
    found = kind(run.loop, place)
    if found == GOALS:
        return kinematic(run)
    if found == ZOO:
        return zoo(run)
    if found == SETUP:
        return setup(run)
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
        law(GOALS, p["family"], p["law_name"], json.loads(p["gains"]), robot),
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
        figures=False,
    )
    report, session = judged_experiment(options)  # the run its report judged
    whole_recording(report)
    diagnostics = messages(session, CONTROL_DIAGNOSTICS)
    since = converged_at(diagnostics, messages(session, SUPERVISOR_STATUS))
    moving = [
        d.nonzero
        for d in diagnostics
        if d.status == "optimal" and d.error_norm is not None and d.error_norm > MOVING_ERROR
    ]
    return {name: report.get(name) for name in EXPERIMENT_FIGURES} | {
        "converge_s": TIME_LIMIT_S if since is None else since - origin_s(session),
        "nonzero_moving": moving,
        "report": json_text(report),
    }


def whole_recording(report: dict[str, Any]) -> None:
    """RuntimeError (the run failed, and is tried again) when the experiment's recording does
    not hold the whole run: figures judged from a recording cut short would be wrong, such as a
    converged run judged not converged because its last states were lost."""
    if not report["recording"]["whole"]:
        raise RuntimeError(
            "its recording is not whole: " + "; ".join(report["recording"]["missing"])
        )


def setup(run: Run) -> dict[str, Any]:
    """The experiment's set-up of the run's seed, kinematically: its law (``places.law``) from
    the set-up's start to the goal above its bin, ``q += u dt`` at 50 Hz for at most the
    experiment's ``TIME_LIMIT_S``, converged at ``||e||`` under ``CONVERGED_ERROR``."""
    p = run.parameters
    robot = MobileManipulator.from_yaml(run.robot_file)
    scene = load_profile(PROFILES["lp"]).scene
    drawn = scenario(p["experiment"], robot, p["seed"])
    height = scene.goal.height_m if drawn.goal_height is None else drawn.goal_height
    offset = scene.goal.offset if drawn.goal_offset is None else drawn.goal_offset
    found = integrate(
        law(SETUP, p["experiment"], p["law_name"], json.loads(p["gains"]), robot),
        np.array(drawn.start),
        PoseTask(drawn.goal(height, offset)),
        DT,
        round(TIME_LIMIT_S / DT),
        CONVERGED_ERROR,
        drawn.obstacles,
    )
    bases = np.array(found.configurations)[:, :2]
    clearance = least_clearance(bases, drawn.obstacles, robot.base.body_radius)
    return {
        "converged": found.converged,
        "contacts": int(clearance < 0.0),
        "min_obstacle_clearance_m": clearance,
        "final_error": found.final_error,
        "converge_s": len(found.outputs) * DT,
        "nonzero_moving": [o.nonzero for o in found.outputs if o.error_norm > MOVING_ERROR],
    }


def zoo(run: Run) -> dict[str, Any]:
    """One goal of the zoo (``studies.redundancy``): the goal drawn ``goal``-th from the run's
    seed on the run's robot, its pose or its position, for at most its ``TIME_LIMIT_S``."""
    p = run.parameters
    robot = MobileManipulator.from_yaml(run.robot_file)
    start, goal = redundancy.draw(robot, p["goal"] + 1, p["seed"])[p["goal"]]
    made = law(ZOO, ZOO_FAMILY, p["law_name"], json.loads(p["gains"]), robot)
    found = redundancy.run_one(made, robot, p["task"], start, goal, redundancy.TIME_LIMIT_S)
    return {
        "reached": found.reached,
        "within_limits": found.within_limits,
        "seconds": found.seconds,
        "nonzero": found.nonzero.tolist(),
        "engaged": found.engaged.tolist(),
        "error": found.error.tolist(),
    }
