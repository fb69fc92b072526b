"""The figures and the control-effort table of section 6.2, from recorded sessions.

A session maps a topic name (``messages.topics``) to the messages recorded on it. It needs
``robot/state``, ``control/goal``, ``base/command``, ``arm/command`` and
``control/diagnostics``; ``world/obstacles`` and ``sim/truth`` are drawn when present. The goal
is the operator's, ``goal/request``, when a staging supervisor stood between it and
``control/goal`` (whose drive legs are not the goal), else ``control/goal``.
Commands and diagnostics carry the stamp of the state they answer, so the control input
u = [x', y', phi', one per arm joint] of a stamp joins the base and arm commands of that stamp with
x' = v cos(phi), y' = v sin(phi), phi' = omega, phi the heading of the nearest state.
Times are in s from the session's first command.

``write_report`` draws (``analysis.report_figures``) one or two sessions (e.g. the LP and the
cascade law) side by side:

    control_inputs.png     u over time (figs. 6.6, 6.11)
    nonzero_entries.png    nonzero entries of u per iteration, and the practical count (6.7, 6.8)
    error.png              e = x - x_d of the end effector, or p - p_d for a position task (6.9)
    joints.png             each arm joint, named as the robot's description names it, against
                           its limits, dashed green (6.10)
    end_effector_path.png  x-y of the end effector and the goal (6.14)
    base_path.png          x-y of the base from its first valid estimate (before the first
                           camera fix the estimate is a placeholder at (0, 0)) and the
                           obstacles: the circles, each table's (or underside's) footprint,
                           each pole, each wall where it meets the floor
    arm_clearance.png      each collision part's clearance from the nearest solid in 3-D over
                           time, from the ground truth (``analysis.judge.arm_clearances``, whose
                           least is the judge's ``arm_clearance_m``); written when a session's
                           truth has solids
    effort.json, effort.md the four metrics of table 6.1 (``analysis.commands.effort_of_inputs``)
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from analysis.commands import Array, commands, effort_of_inputs, required
from analysis.judge import arm_clearances, open_loop
from analysis.report_figures import FIGURES, RecordedSession
from analysis.run_end import Session, messages
from messages.topics import (
    CONTROL_DIAGNOSTICS,
    CONTROL_GOAL,
    GOAL_REQUEST,
    ROBOT_STATE,
    SIM_TRUTH,
    WORLD_OBSTACLES,
)
from record.session_span import parted
from wbc import dq
from wbc.planar import in_frame, planar_pose
from wbc.robot import MobileManipulator

FORMULAS: Mapping[str, str] = {
    "metric1": r"$\int \lVert\dot{q}\rVert_1\,dt$",
    "metric2": r"$\sqrt{\int \lVert\dot{q}\rVert_2^2\,dt}$",
    "metric3": r"$\int \lVert\ddot{q}\rVert_1\,dt$",
    "metric4": r"$\sqrt{\int \lVert\ddot{q}\rVert_2^2\,dt}$",
}
"""Table 6.1's metrics (``analysis.commands.METRICS``) as formulas."""


def control_inputs(session: Session) -> tuple[Array, Array]:
    """(t, u): times in s from the first command, and one row u = [x', y', phi', arm joints']
    per stamp that has both a base and an arm command."""
    stamps, u = commands(session)
    return (stamps - stamps[0]) * 1e-9, u


def write_report(
    sessions: Sequence[tuple[str, Session]],
    robot: MobileManipulator,
    out: Path,
    truth_frame: tuple[float, float, float] | None = None,
) -> dict:
    """Write the figures and effort table of one or two (label, session) pairs into ``out``.

    The estimates are in the frame of the reference marker F0; the simulator's truth is in its
    own world. ``truth_frame`` is F0's (x, y, yaw) there (the scene's ``reference_pose``): the
    truth is drawn in F0's frame beside the estimate; None draws no truth.

    Every session is checked before anything is written; a missing or empty topic raises
    ``ValueError`` naming it. Messages stamped far outside a session are left out
    (``record.session_span``). A figure the data cannot give (``ValueError``, an arithmetic
    fault) is not written and said in ``gaps``; ``notes`` say what a reader must know to read
    the figures (a rerun's commands, ``analysis.judge.open_loop``). Returns ``{"figures":
    [paths], "effort": {label: metrics}, "gaps": {figure: why}, "notes": [lines]}``.
    """
    labels = [label for label, _ in sessions]
    if not 1 <= len(sessions) <= 2:
        raise ValueError(f"a report compares one or two sessions, got {len(sessions)}")
    if len(set(labels)) != len(labels):
        raise ValueError(f"session labels must differ, got {labels}")
    recordings = [_recording(label, session, truth_frame, robot) for label, session in sessions]
    efforts = {rec.label: effort_of_inputs(rec.stamps_ns, rec.u) for rec in recordings}
    if short := [label for label, found in efforts.items() if found is None]:
        raise ValueError(f"{', '.join(short)}: the control effort needs two commands or more")
    notes = [
        OPEN_LOOP_NOTE.format(label=label) for label, session in sessions if open_loop(session)
    ]
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    figures, gaps = [], {}
    for name, draw in FIGURES.items():
        try:
            figure = draw(recordings, robot)
            if figure is not None:
                figure.savefig(out / name, dpi=100)
                figures.append(out / name)
        except (ValueError, ArithmeticError) as error:
            (out / name).unlink(missing_ok=True)
            gaps[name] = str(error).splitlines()[0] if str(error) else type(error).__name__
    (out / "effort.json").write_text(json.dumps(efforts, indent=2) + "\n")
    (out / "effort.md").write_text(_effort_table(efforts, notes))
    return {"figures": figures, "effort": efforts, "gaps": gaps, "notes": notes}


OPEN_LOOP_NOTE = (
    "{label}: its commands were computed by `parsimony rerun` on the recording's "
    "states, not in a closed loop (the states did not follow them): its effort "
    "is not that of a run of its law"
)
"""What a report says of a session whose commands a rerun computed."""


def _in_frame(truth: Any, frame: tuple[float, float, float]) -> Any:
    """A SimTruth seen from ``frame`` (x0, y0, yaw0): p' = R(-yaw0)(p - p0), x' = F* x."""
    base = in_frame(*truth.base_pose, frame)
    pose = dq.normalize(dq.mul(dq.conj(planar_pose(*frame)), np.array(truth.end_effector)))
    return truth.model_copy(update={"base_pose": base, "end_effector": tuple(pose.tolist())})


def _recording(
    label: str,
    session: Session,
    truth_frame: tuple[float, float, float] | None,
    robot: MobileManipulator,
) -> RecordedSession:
    session = parted(session).kept
    stamps, u = commands(session)
    states = required(session, ROBOT_STATE)
    if len(states[0].arm_joints) != robot.arm_dof:
        raise ValueError(
            f"the robot description has {robot.arm_dof} arm joints, the "
            f"recording's states {len(states[0].arm_joints)}"
        )
    names = tuple(getattr(states[0], "joint_names", None) or robot.joint_names)
    if names != robot.joint_names:
        raise ValueError(
            f"the robot description's joints are {', '.join(robot.joint_names)}, the "
            f"recording's states' {', '.join(names)}"
        )
    recorded = messages(session, SIM_TRUTH)
    truth = recorded if truth_frame is not None else []
    clearance = arm_clearances(recorded, robot)  # the same in any frame: no truth_frame needed
    stamped = np.array([t.header.stamp_ns for t in recorded], dtype=np.int64)
    return RecordedSession(
        label=label,
        stamps_ns=stamps,
        u=u,
        states=states,
        goals=messages(session, GOAL_REQUEST) or required(session, CONTROL_GOAL),
        diagnostics=required(session, CONTROL_DIAGNOSTICS),
        obstacles=messages(session, WORLD_OBSTACLES),
        truth=[_in_frame(t, truth_frame) for t in truth],
        arm_clearance=None if clearance is None else ((stamped - stamps[0]) * 1e-9, clearance),
    )


def _effort_table(efforts: Mapping[str, Mapping[str, float]], notes: Sequence[str] = ()) -> str:
    labels = [label.replace("|", r"\|") for label in efforts]
    lines = [
        "Control effort (table 6.1)",
        "",
        "| | Metric | " + " | ".join(labels) + " |",
        "| :-: | :-- |" + " --: |" * len(labels),
    ]
    for number, (name, formula) in enumerate(FORMULAS.items(), start=1):
        values = " | ".join(f"{metrics[name]:.4g}" for metrics in efforts.values())
        lines.append(f"| {number} | {formula} | {values} |")
    lines.extend(f"\nNote: {note}." for note in notes)
    return "\n".join(lines) + "\n"
