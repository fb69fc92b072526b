"""A run judged from its recording alone: every figure ``report.json`` gives about a run.

A session maps a topic name to its messages (``record.sessions.load_session`` of
``JUDGED``). The run begins at its first ground truth (its first state on a robot without one)
and ends ``HOLD_S`` after the controller's error fell under ``CONVERGED_ERROR`` for good, under
a supervisor within its last pose phase (a drive leg's error is not the goal's); else at the
time limit, or at the last step. What is judged against the simulator's ground truth
(``sim/truth``, which no component of the loop reads: the true final error, the estimator's
error in the steady state, contacts, joints at their hard stops, clearance) is None, and
``truth`` says ``absent``, for a recording without it (a real robot's). The control inputs
u = [x', y', phi', a velocity per arm joint of the robot's description] join the base and arm
commands of one stamp with x' = v cos(phi) - l sin(phi), y' = v sin(phi) + l cos(phi) (l the
lateral speed of an omnidirectional base, else 0), phi the heading of the nearest state: the
estimate the controller turned u into the base's command with.
"""

from __future__ import annotations

import hashlib
import math
import struct
from collections import Counter
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

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
    Topic,
)
from record.session_span import parted
from wbc import dq
from wbc.geometry.arm_clearance import part_clearances
from wbc.geometry.obstacles import least_clearance
from wbc.laws.kinematic_run import effort_of
from wbc.planar import in_frame, wrap
from wbc.planning.supervisor_phase import Phase
from wbc.robot import MobileManipulator

Array = np.ndarray
Session = Mapping[str, Sequence[Any]]

CONVERGED_ERROR = 0.01
"""The controller's error norm ||e|| under which the goal counts as reached."""
HOLD_S = 2.0
"""Simulated seconds the error must stay under ``CONVERGED_ERROR``; also the steady state."""
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
METRICS: Mapping[str, str] = {
    "metric1": "velocity_l1",
    "metric2": "velocity_l2",
    "metric3": "acceleration_l1",
    "metric4": "acceleration_l2",
}
"""Table 6.1's metrics: the ``ControlEffort`` field each reports."""


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


def the_run(session: Session, time_limit_s: float | None = None) -> tuple[dict[str, list], bool]:
    """The messages of the run, up to its end (``end_of_run``), and whether it converged: what
    is judged, and what a report draws. Messages stamped far outside the session
    (``record.session_span``) are left out."""
    session = parted(session).kept
    end_ns, converged = end_of_run(session, time_limit_s, origin_s(session))
    return until(session, end_ns), converged


def messages(session: Session, topic: Topic) -> list:
    """The messages of ``topic`` in stamp order (none when the session has none)."""
    return sorted(session.get(topic.name) or [], key=lambda m: m.header.stamp_ns)


def origin_s(session: Session) -> float:
    """When the run began: its first ground truth (0 in lockstep, the host's clock when the
    simulator keeps host time), else its first state; s (inf for an empty session)."""
    first = messages(session, SIM_TRUTH)[:1] or messages(session, ROBOT_STATE)[:1]
    return first[0].header.stamp_ns / 1e9 if first else math.inf


CONVERGING = frozenset(("direct", Phase.POSE, Phase.REACHED))
"""The supervisor's phases in which the controller steps on the goal's own task: a pose goal's
pose phase, a goal of another kind passed on as it is (``direct``), and either once reached."""


def converged_at(diagnostics: Sequence, statuses: Sequence) -> float | None:
    """The time since which every step's error stayed under ``CONVERGED_ERROR``; under a
    supervisor (``statuses``), only the steps of its last run of ``CONVERGING`` phases count."""
    pose_since = pose_phase_since(statuses)
    if pose_since is None:
        return None
    since = None
    for d in diagnostics:
        if d.header.stamp_ns / 1e9 < pose_since:
            continue
        small = d.status == "optimal" and d.error_norm is not None
        if not (small and d.error_norm < CONVERGED_ERROR):
            since = None
        elif since is None:
            since = d.header.stamp_ns / 1e9
    return since


def pose_phase_since(statuses: Sequence) -> float | None:
    """When the supervisor's last run of ``CONVERGING`` phases began; 0 with no supervisor,
    None while it is in another phase."""
    if not statuses:
        return 0.0
    since = None
    for status in statuses:
        if status.phase not in CONVERGING:
            since = None
        elif since is None:
            since = status.header.stamp_ns / 1e9
    return since


def end_of_run(session: Session, time_limit_s: float | None, origin: float) -> tuple[int, bool]:
    """The stamp (ns) the run ends at, ``HOLD_S`` after it converged, else ``time_limit_s``
    after ``origin``, else its last step; and whether it converged. The limit is a simulated
    time, and what came after it is not looked at: two lockstep runs of one set-up judge the
    same steps, however long each went on before it was stopped."""
    limited = time_limit_s is not None and math.isfinite(origin)
    limit_ns = round((origin + time_limit_s) * 1e9) if limited else None
    within = (
        session
        if limit_ns is None
        else until(
            {t.name: session.get(t.name) or [] for t in (CONTROL_DIAGNOSTICS, SUPERVISOR_STATUS)},
            limit_ns,
        )
    )
    diagnostics = messages(within, CONTROL_DIAGNOSTICS)
    since = converged_at(diagnostics, messages(within, SUPERVISOR_STATUS))
    if since is not None and diagnostics[-1].header.stamp_ns / 1e9 - since >= HOLD_S:
        return round((since + HOLD_S) * 1e9), True
    if limit_ns is not None:
        return limit_ns, False
    return (diagnostics[-1].header.stamp_ns if diagnostics else 0), False


def until(session: Session, end_ns: int) -> dict[str, list]:
    """The messages stamped up to ``end_ns``."""
    return {n: [m for m in ms if m.header.stamp_ns <= end_ns] for n, ms in session.items()}


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


def nearest(sorted_stamps: Array, stamps: Array) -> Array:
    """The index into ``sorted_stamps`` (not empty) of the one nearest each of ``stamps``."""
    if len(sorted_stamps) == 1:
        return np.zeros(len(stamps), dtype=int)
    after = np.clip(np.searchsorted(sorted_stamps, stamps), 1, len(sorted_stamps) - 1)
    before = after - 1
    nearer_before = stamps - sorted_stamps[before] <= sorted_stamps[after] - stamps
    return np.where(nearer_before, before, after)


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


def commands(session: Session) -> tuple[Array, Array]:
    """(stamps in ns, u rows) of the stamps that have a base and an arm command, and a state
    to take the heading from; ``ValueError`` naming what is missing."""
    base = {m.header.stamp_ns: m for m in required(session, BASE_COMMAND)}
    arm = {m.header.stamp_ns: m for m in required(session, ARM_COMMAND)}
    stamps = np.array(sorted(base.keys() & arm.keys()), dtype=np.int64)
    if stamps.size == 0:
        raise ValueError(
            f"no {BASE_COMMAND.name!r} message shares a stamp with {ARM_COMMAND.name!r}"
        )
    states = required(session, ROBOT_STATE)
    state_stamps = np.array([s.header.stamp_ns for s in states], dtype=np.int64)
    phi = np.array([states[i].base_pose[2] for i in nearest(state_stamps, stamps)])
    v = np.array([base[s].forward_velocity for s in stamps])
    omega = np.array([base[s].angular_velocity for s in stamps])
    joints = np.array([arm[s].joint_velocities for s in stamps])
    if not any(base[s].lateral_velocity for s in stamps):  # as a differential base's always
        return stamps, np.column_stack((v * np.cos(phi), v * np.sin(phi), omega, joints))
    side = np.array([base[s].lateral_velocity for s in stamps])  # to the base's left
    cos, sin = np.cos(phi), np.sin(phi)
    return stamps, np.column_stack((v * cos - side * sin, v * sin + side * cos, omega, joints))


def required(session: Session, topic: Topic) -> list:
    """The messages of ``topic`` in stamp order; ``ValueError`` naming it when there are none
    or they are not of its type."""
    found = messages(session, topic)
    if not found:
        raise ValueError(f"the session has no messages on topic {topic.name!r}")
    wrong = [type(m).__name__ for m in found if not isinstance(m, topic.type)]
    if wrong:
        raise ValueError(f"topic {topic.name!r} carries {topic.type.__name__}, got {wrong[0]}")
    return found


def effort(session: Session) -> dict[str, float] | None:
    """Table 6.1's metrics of the control inputs, with dt the median command period, as
    ``metric1`` .. ``metric4``; None with fewer than two commands."""
    try:
        stamps, u = commands(session)
    except ValueError:
        return None
    return effort_of_inputs(stamps, u)


def effort_of_inputs(stamps_ns: Array, u: Array) -> dict[str, float] | None:
    """``effort_of`` rows of u stamped ``stamps_ns``, dt their median period."""
    if len(stamps_ns) < 2:
        return None
    metrics = effort_of(u, float(np.median(np.diff(stamps_ns))) * 1e-9)
    return {name: getattr(metrics, field) for name, field in METRICS.items()}


def commands_digest(session: Session) -> str:
    """SHA-256 of every command's stamp and values in stamp order: two runs that sent the same
    commands have the same digest (a field at its default, such as a differential base's
    ``lateral_velocity`` 0, is left out: the digests of older runs hold)."""
    digest = hashlib.sha256()
    for topic in (BASE_COMMAND, ARM_COMMAND):
        for command in messages(session, topic):
            values = command.model_dump(exclude={"header", "joint_names"}, exclude_defaults=True)
            digest.update(struct.pack("<q", command.header.stamp_ns))
            digest.update(repr(sorted(values.items())).encode())
    return digest.hexdigest()


def commands_csv(session: Session, robot: MobileManipulator) -> str:
    """Every command pair the controller sent, one row per stamp (s, m/s, rad/s), the lateral
    speed after the angular on an omnidirectional base, a column per joint of the robot's arm,
    named as its description names it (``<name>_dot``)."""
    arm = {a.header.stamp_ns: a.joint_velocities for a in messages(session, ARM_COMMAND)}
    lateral = robot.base.kind == "omnidirectional"
    base = "stamp_s,forward,angular," + ("lateral," if lateral else "")
    lines = [base + ",".join(f"{n}_dot" for n in robot.joint_names)]
    for b in messages(session, BASE_COMMAND):
        joints = arm.get(b.header.stamp_ns)
        if joints is not None:
            side = (b.lateral_velocity,) if lateral else ()
            values = (b.forward_velocity, b.angular_velocity, *side, *joints)
            lines.append(f"{b.header.stamp_ns / 1e9:.3f}," + ",".join(repr(v) for v in values))
    return "\n".join(lines) + "\n"


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
