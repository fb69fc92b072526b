"""A run judged from its recording alone: every figure ``report.json`` gives about a run.

A session maps a topic name to its messages (``record.sessions.load_session`` of
``JUDGED``). The run is judged up to its end (``analysis.run_end``). What is judged against the
simulator's ground truth (``sim/truth``, which no component of the loop reads: the true final
error, the estimator's error in the steady state, contacts, joints at their hard stops,
clearance) is None, and ``truth`` says ``absent``, for a recording without it (a real robot's).
The effort and the digest are of the control inputs its commands give (``analysis.commands``).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from typing import Any

import numpy as np

from analysis.commands import Array, commands_digest, effort, nearest
from analysis.run_end import HOLD_S, Session, messages, the_run
from messages.topics import (
    ARM_COMMAND,
    BASE_COMMAND,
    CONTROL_DIAGNOSTICS,
    CONTROL_GOAL,
    GOAL_REQUEST,
    ROBOT_STATE,
    SIM_TRUTH,
    SUPERVISOR_STATUS,
    WORLD_OBSTACLES,
)
from record.session_span import parted
from wbc import dq
from wbc.geometry.arm_clearance import part_clearances
from wbc.geometry.obstacles import least_clearance
from wbc.planar import in_frame, wrap
from wbc.robot import MobileManipulator

JUDGED = frozenset(
    t.name
    for t in (
        ROBOT_STATE,
        CONTROL_GOAL,
        GOAL_REQUEST,
        BASE_COMMAND,
        ARM_COMMAND,
        CONTROL_DIAGNOSTICS,
        WORLD_OBSTACLES,
        SIM_TRUTH,
        SUPERVISOR_STATUS,
    )
)
"""The topics a run is judged (and its figures drawn) from: no images."""
RERUN_SOURCE = "rerun_"
"""The source of the commands ``parsimony rerun`` computes, before the law's name: offline, on
a recording's states, which did not follow them."""


def judge(
    session: Session, robot: MobileManipulator, time_limit_s: float | None = None
) -> dict[str, Any]:
    """Every figure of the run ``session`` holds, up to its end (``the_run``);
    ``outside_session`` says in one line what was left out as stamped far outside the session
    (``record.session_span``), None when nothing was; ``open_loop`` whether its commands were
    computed offline by a rerun."""
    outside = parted(session).line()
    run, converged = the_run(session, time_limit_s)
    truth, states = messages(run, SIM_TRUTH), messages(run, ROBOT_STATE)
    diagnostics = messages(run, CONTROL_DIAGNOSTICS)
    steps = [d for d in diagnostics if d.status == "optimal"]
    solve = np.array([d.solve_time_us for d in steps]) if steps else np.zeros(1)
    end_s = diagnostics[-1].header.stamp_ns / 1e9 if diagnostics else 0.0
    return {
        "converged": converged,
        "truth": "recorded" if truth else "absent",
        "final_error": final_error(truth, run),
        "final_error_estimated": diagnostics[-1].error_norm if diagnostics else None,
        "sim_time_s": round(_span_s(truth or states), 3),
        "iterations": len(diagnostics),
        "contacts": truth[-1].contacts if truth else None,
        "supervisor": supervisor_summary(messages(run, SUPERVISOR_STATUS)),
        "joint_limit_violations": joints_at_stops(truth, robot) if truth else None,
        "min_obstacle_clearance_m": clearance(truth, robot),
        "arm_penetrations": truth[-1].arm_penetrations if truth else None,
        "arm_clearance_m": arm_clearance(truth, robot),
        "estimator_error": estimator_error(truth, states, end_s - HOLD_S),
        "nonzero_entries": dict(sorted(Counter(d.nonzero for d in steps).items())),
        "effort": effort(run),
        "step_time_us": {
            "median": round(float(np.median(solve)), 1),
            "p99": round(float(np.percentile(solve, 99)), 1),
        },
        "controller_statuses": dict(sorted(Counter(d.status for d in diagnostics).items())),
        "degraded_states": sum(s.degraded for s in states),
        "invalid_states": sum(not s.valid for s in states),
        "commands_digest": commands_digest(run),
        "outside_session": outside,
        "open_loop": open_loop(run),
    }


def open_loop(session: Session) -> bool:
    """Whether the session's commands were computed by ``parsimony rerun`` (``RERUN_SOURCE``)
    on recorded states, not in a closed loop."""
    return any(c.header.source.startswith(RERUN_SOURCE) for c in messages(session, BASE_COMMAND))


def _span_s(samples: Sequence) -> float:
    return (samples[-1].header.stamp_ns - samples[0].header.stamp_ns) / 1e9 if samples else 0.0


def final_error(truth: Sequence, session: Session) -> float | None:
    """||x - x_d|| of the true end effector at the end against the true goal (the translation
    alone for a position task); None without the truth or its goal."""
    if not truth or truth[-1].goal is None:
        return None
    x, goal = np.array(truth[-1].end_effector), np.array(truth[-1].goal)
    goals = messages(session, GOAL_REQUEST) or messages(session, CONTROL_GOAL)
    if goals and goals[-1].task == "position":
        return float(np.linalg.norm(dq.translation(x) - dq.translation(goal)))
    return float(np.linalg.norm(x - dq.nearest_equivalent(goal, x)))


def supervisor_summary(statuses: Sequence) -> dict[str, Any] | None:
    """The staging supervisor's last word: phase, plans, re-plans, stalls, reason; and when
    each phase began (s). None when the run had no supervisor."""
    if not statuses:
        return None
    last = statuses[-1]
    began: list[tuple[str, float]] = []
    for status in statuses:
        if not began or began[-1][0] != status.phase:
            began.append((status.phase, status.header.stamp_ns / 1e9))
    return {
        "phase": last.phase,
        "plans": last.plans,
        "replans": last.replans,
        "stalls": last.stalls,
        "reason": last.reason,
        "candidate_base": last.candidate_base,
        "phases": [{"phase": p, "from_s": t} for p, t in began],
    }


def joints_at_stops(truth: Sequence, robot: MobileManipulator) -> int:
    """Ground-truth samples with an arm joint at (or past) its limit: the simulated servo's
    hard stop. The LP's joint constraint (5.14) keeps them inside."""
    arm = np.array([t.arm_joints for t in truth])
    low, high = robot.q_min[3:], robot.q_max[3:]
    return int(np.any((arm <= low + 1e-9) | (arm >= high - 1e-9), axis=1).sum())


def clearance(truth: Sequence, robot: MobileManipulator) -> float | None:
    """The least distance between the base's disc and an obstacle, m (None without either)."""
    if not truth or not truth[-1].obstacles:
        return None
    bases = np.array([t.base_pose[:2] for t in truth])
    return round(least_clearance(bases, truth[-1].obstacles, robot.base.body_radius), 4)


def arm_clearances(truth: Sequence, robot: MobileManipulator) -> Array | None:
    """(samples, parts): the clearance of each collision part of the robot (``robot.collision
    .names``) from the nearest solid in 3-D at each ground-truth sample, m (negative: the depth
    of a penetration), from the true configurations (``wbc.geometry.arm_clearance``); None without
    the truth or solids."""
    if not truth or not truth[-1].solids.solids() or not robot.collision.names:
        return None
    solids = truth[-1].solids.solids()
    return np.array(
        [part_clearances(robot, np.array(t.configuration()), solids).min(axis=1) for t in truth]
    )


def arm_clearance(truth: Sequence, robot: MobileManipulator) -> dict[str, float] | None:
    """The least clearance of each collision part from the solids in 3-D over the run, m
    (negative: the deepest penetration; ``arm_clearances``); None without the truth or
    solids."""
    found = arm_clearances(truth, robot)
    if found is None:
        return None
    least = found.min(axis=0)
    return {
        name: round(float(value), 4)
        for name, value in zip(robot.collision.names, least, strict=True)
    }


NEAR_NS = 20_000_000
"""A truth sample stands for a state when their stamps are this close (the same stamp in
lockstep; on host time, as with emulated devices, the step nearest the driver's reading)."""


def estimator_error(truth: Sequence, states: Sequence, since_s: float) -> dict:
    """The largest base position and heading error of the valid estimates stamped after
    ``since_s`` (the steady state) against the truth, both in F0's frame; None without the
    truth."""
    usable = [s for s in states if s.valid and s.header.stamp_ns / 1e9 >= since_s]
    if not truth or truth[-1].reference_pose is None or not usable:
        return {"position_m": None, "angle_rad": None, "samples": 0}
    truth_stamps = np.array([t.header.stamp_ns for t in truth], dtype=np.int64)
    stamps = np.array([s.header.stamp_ns for s in usable], dtype=np.int64)
    position, angle = [], []
    for state, index in zip(usable, nearest(truth_stamps, stamps), strict=True):
        if abs(truth_stamps[index] - state.header.stamp_ns) > NEAR_NS:
            continue
        sample = truth[index]
        x, y, phi = in_frame(*sample.base_pose, sample.reference_pose)
        position.append(math.hypot(state.base_pose[0] - x, state.base_pose[1] - y))
        angle.append(abs(wrap(state.base_pose[2] - phi)))
    if not position:
        return {"position_m": None, "angle_rad": None, "samples": 0}
    return {
        "position_m": round(max(position), 5),
        "angle_rad": round(max(angle), 5),
        "samples": len(position),
    }


def recording_check(facts: dict[str, Any], run_ns: tuple[int, int]) -> dict:
    """Whether the recording (``facts``: its ``info``) holds the whole run, from its first state
    to its last (``run_ns``): its footer, no sample dropped by the recorder, and the run's
    states from start to end; ``missing`` says what is not there (empty when whole). With its
    size, and bytes per simulated second."""
    start_ns, end_ns = run_ns
    missing = []
    if not facts["complete"]:
        missing.append("no footer: the recorder was killed, the file keeps its complete chunks")
    if facts["dropped"]:
        lost = ", ".join(f"{n} ({counter})" for counter, n in facts["dropped"].items())
        missing.append(f"the recorder lost {lost}")
    states = [c for c in facts["channels"] if c["key"].endswith("/" + ROBOT_STATE.name)]
    first_ns = min((c["start_ns"] for c in states), default=0)
    last_ns = max((c["end_ns"] for c in states), default=0)
    if not states or first_ns > start_ns:
        missing.append(f"its states begin {(first_ns - start_ns) / 1e9:.2f} s after the run's")
    if last_ns < end_ns:
        missing.append(f"its states end {(end_ns - last_ns) / 1e9:.2f} s before the run's")
    span_s = max((end_ns - start_ns) / 1e9, 1e-9)
    return {
        "whole": not missing,
        "missing": missing,
        "messages": facts["messages"],
        "bytes": facts["bytes"],
        "bytes_per_sim_s": round(facts["bytes"] / span_s),
    }
