"""A run of the whole loop read back from its recording, as the rows of `parsimony reproduce`
take a kinematic run (``wbc.laws.kinematic_run.Run``).

The run is what ``analysis.judge`` judges (``analysis.run_end``: up to ``HOLD_S`` after the
controller's error stayed under ``CONVERGED_ERROR``, else the time limit), from the controller's
first step of its law on: one step per diagnostics that answers a state, with u as its commands
carried it (``analysis.commands.commands``: the base's (v, omega) after the wheel speed limit, in
F0), the state the controller was given (the estimate, in F0), the task of the last goal it held,
its diagnostics (status, rows at their bound, the law's step time, its error) and the simulator's
true configuration at that stamp (in the simulator's world, the kinematic runs' frame).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.commands import commands, nearest, required
from analysis.judge import JUDGED
from analysis.run_end import the_run
from components.control_step import task_of
from messages.topics import CONTROL_DIAGNOSTICS, CONTROL_GOAL, ROBOT_STATE, SIM_TRUTH
from record.sessions import load_session
from wbc import dq
from wbc.laws.kinematic_run import Run
from wbc.laws.law_output import LawOutput
from wbc.task import PoseTask, PositionTask, Task


@dataclass(frozen=True)
class Recorded:
    """A recorded run: the controller's view, the truth beside it, and each step's task."""

    run: Run
    """The estimated configurations (F0) and each step's output."""
    truth: Run
    """The true configurations (the simulator's world) and the same outputs."""
    tasks: list[Task]
    """The task of each step: the last goal the controller held (F0)."""
    goal: Task
    """The goal as the simulator placed it (its world), of the goals' kind."""


def recorded(path: Path, time_limit_s: float) -> Recorded:
    """The run ``path`` holds; ``ValueError`` saying what the recording lacks."""
    run, converged = the_run(load_session(path, JUDGED), time_limit_s)
    stamps, u = commands(run)
    inputs = dict(zip(stamps.tolist(), u, strict=True))
    states = {s.header.stamp_ns: s for s in required(run, ROBOT_STATE)}
    steps = [
        d
        for d in required(run, CONTROL_DIAGNOSTICS)
        if d.header.stamp_ns in states and d.header.stamp_ns in inputs
    ]
    first = next((i for i, d in enumerate(steps) if d.status == "optimal"), None)
    if first is None:
        raise ValueError(f"{path}: the controller never stepped its law (no optimal step)")
    steps = steps[first:]
    goals = required(run, CONTROL_GOAL)
    goal_stamps = np.array([g.header.stamp_ns for g in goals], dtype=np.int64)
    truth = required(run, SIM_TRUTH)
    truth_stamps = np.array([t.header.stamp_ns for t in truth], dtype=np.int64)
    step_stamps = np.array([d.header.stamp_ns for d in steps], dtype=np.int64)
    held = np.searchsorted(goal_stamps, step_stamps, side="right") - 1
    dt = float(np.median(np.diff(step_stamps))) * 1e-9 if len(steps) > 1 else 0.02
    outputs, error = [], math.nan
    for d in steps:
        error = d.error_norm if d.error_norm is not None else error  # a zero step: the last
        outputs.append(
            LawOutput(
                inputs[d.header.stamp_ns],
                d.status,
                d.objective,
                d.nonzero,
                d.practical_nonzero,
                d.active_constraints,
                d.solve_time_us * 1e-6,
                error,
            )
        )
    estimated = Run(
        dt=dt,
        outputs=outputs,
        reached=converged,
        configurations=[np.array(states[s].configuration()) for s in step_stamps],
    )
    true = Run(
        dt=dt,
        outputs=outputs,
        reached=converged,
        configurations=[
            np.array(truth[i].configuration()) for i in nearest(truth_stamps, step_stamps)
        ],
    )
    kind = task_of(goals[-1])
    placed = np.array(truth[-1].goal) if truth[-1].goal is not None else None
    if placed is None:
        raise ValueError(f"{path}: its ground truth does not say where the goal was placed")
    goal = (
        PositionTask(dq.translation(placed)[1:])
        if isinstance(kind, PositionTask)
        else PoseTask(placed)
    )
    made = {i: task_of(goals[i]) for i in set(held.tolist())}
    return Recorded(estimated, true, [made[i] for i in held.tolist()], goal)
