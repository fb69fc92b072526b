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

``write_report`` draws one or two sessions (e.g. the LP and the cascade law) side by side:

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
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from analysis.commands import Array, commands, effort_of_inputs, required
from analysis.judge import arm_clearances, open_loop
from analysis.run_end import Session, messages
from messages.goal import Goal
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

if TYPE_CHECKING:  # matplotlib is imported by the first figure drawn, not by every command
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

FORMULAS: Mapping[str, str] = {
    "metric1": r"$\int \lVert\dot{q}\rVert_1\,dt$",
    "metric2": r"$\sqrt{\int \lVert\dot{q}\rVert_2^2\,dt}$",
    "metric3": r"$\int \lVert\ddot{q}\rVert_1\,dt$",
    "metric4": r"$\sqrt{\int \lVert\ddot{q}\rVert_2^2\,dt}$",
}
"""Table 6.1's metrics (``analysis.commands.METRICS``) as formulas."""

END_EFFECTOR_TASKS = ("pose", "position")
"""The goals that give the end effector a target (a drive leg's aims the base)."""

BASE_INPUTS = ("x'", "y'", "phi'")
"""The base's entries of u, first."""


def input_names(robot: MobileManipulator) -> tuple[str, ...]:
    """The entries of u, in order: the base's, then each arm joint's by its name."""
    return BASE_INPUTS + tuple(f"{name}'" for name in robot.joint_names)


def joint_unit(robot: MobileManipulator, joint: int) -> str:
    """The unit of arm joint ``joint`` (0-based): m for a prismatic joint, else rad."""
    return "m" if robot.joint_types[joint] == "prismatic" else "rad"


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
    for name, draw in _FIGURES.items():
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


@dataclass(frozen=True)
class _Recording:
    """One session's messages, checked and sorted by stamp, with its control inputs."""

    label: str
    stamps_ns: Array
    u: Array
    states: list
    goals: list
    diagnostics: list
    obstacles: list
    truth: list
    arm_clearance: tuple[Array, Array] | None
    """(t, (samples, parts) clearances) of the ground truth (``analysis.judge.arm_clearances``)."""

    def seconds(self, messages: Sequence[Any]) -> Array:
        """The stamps of ``messages`` in s from the first command."""
        stamps = np.array([m.header.stamp_ns for m in messages], dtype=np.int64)
        return (stamps - self.stamps_ns[0]) * 1e-9

    def command_seconds(self) -> Array:
        """The stamps of the rows of ``u`` in s from the first."""
        return (self.stamps_ns - self.stamps_ns[0]) * 1e-9


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
) -> _Recording:
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
    return _Recording(
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


def _panels(recordings: Sequence[_Recording], rows: int, height: float, **share: Any) -> tuple:
    """A figure with ``rows`` panels per session, sessions side by side, labels as titles."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.0 * len(recordings), height), layout="constrained")
    axes = figure.subplots(rows, len(recordings), squeeze=False, **share)
    for ax, rec in zip(axes[0], recordings, strict=True):
        ax.set_title(rec.label)
    return figure, axes


def _control_inputs_figure(recordings: Sequence[_Recording], robot: MobileManipulator) -> Figure:
    figure, axes = _panels(recordings, 1, 4.0, sharey=True)
    for ax, rec in zip(axes[0], recordings, strict=True):
        t = rec.command_seconds()
        for column, name in enumerate(input_names(robot)):
            ax.plot(t, rec.u[:, column], label=name, linewidth=1.0)
        ax.set(xlabel="t (s)", ylabel="u (m/s, rad/s)")
        ax.legend(ncols=4, fontsize="small")
    return figure


def _nonzero_figure(recordings: Sequence[_Recording], _: MobileManipulator) -> Figure:
    figure, axes = _panels(recordings, 2, 5.0, sharex="col", sharey=True)
    for column, rec in enumerate(recordings):
        iteration = np.arange(len(rec.diagnostics))
        counts = (
            ("nonzero entries", [d.nonzero for d in rec.diagnostics]),
            ("practical nonzero entries", [d.practical_nonzero for d in rec.diagnostics]),
        )
        for ax, (name, count) in zip(axes[:, column], counts, strict=True):
            ax.step(iteration, count, where="post")
            ax.set(ylabel=name, ylim=(-0.5, rec.u.shape[1] + 0.5))
        axes[-1, column].set_xlabel("iteration")
    return figure


def _error_figure(recordings: Sequence[_Recording], _: MobileManipulator) -> Figure:
    figure, axes = _panels(recordings, 1, 4.0, sharey=True)
    for ax, rec in zip(axes[0], recordings, strict=True):
        found = _task_error(rec)
        if found is None:
            _nothing(ax, "no end-effector goal (pose or position) in force at any state")
            continue
        t, error, names = found
        for column, name in enumerate(names):
            ax.plot(t, error[:, column], label=name, linewidth=1.0)
        ax.set(xlabel="t (s)", ylabel="error")
        ax.legend(ncols=4, fontsize="small")
    return figure


def _legend(ax: Axes) -> None:
    """The legend of what a panel drew, if it drew anything labelled."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")


def _nothing(ax: Axes, why: str) -> None:
    """A panel that has nothing to draw says why."""
    ax.text(0.5, 0.5, why, ha="center", va="center", wrap=True, transform=ax.transAxes)


def _task_error(rec: _Recording) -> tuple[Array, Array, tuple[str, ...]] | None:
    """(t, rows of e, names) of the states with an end-effector goal in force: the 8
    coefficients of x - x_d when every such goal is a pose, else the translation error
    p - p_d; None when no state has one (a drive leg's goal aims the base)."""
    goal_stamps = np.array([g.header.stamp_ns for g in rec.goals], dtype=np.int64)
    in_force = []
    for state in rec.states:
        index = int(np.searchsorted(goal_stamps, state.header.stamp_ns, side="right")) - 1
        if index >= 0 and rec.goals[index].task in END_EFFECTOR_TASKS:
            in_force.append((state, rec.goals[index]))
    if not in_force:
        return None
    pose_only = all(goal.task == "pose" for _, goal in in_force)
    rows = []
    for state, goal in in_force:
        x = np.array(state.end_effector)
        if pose_only:
            rows.append(x - dq.nearest_equivalent(np.array(goal.pose), x))
        else:
            rows.append(dq.translation(x)[1:] - _goal_position(goal))
    names = tuple(f"e{i}" for i in range(1, 9)) if pose_only else ("e_x", "e_y", "e_z")
    return rec.seconds([state for state, _ in in_force]), np.array(rows), names


def _goal_position(goal: Goal) -> Array:
    """The end effector's goal position of a pose or position goal."""
    if goal.task == "pose":
        return dq.translation(np.array(goal.pose))[1:]
    return np.array(goal.position)


def _joints_figure(recordings: Sequence[_Recording], robot: MobileManipulator) -> Figure:
    joints = robot.arm_dof
    height = 2.0 * min(joints, 5) + 1.2 * max(joints - 5, 0)  # a long arm's panels lower
    figure, axes = _panels(recordings, joints, height, sharex="col", sharey="row")

    for column, rec in enumerate(recordings):
        t = rec.seconds(rec.states)
        q = np.array([s.arm_joints for s in rec.states])
        for joint, ax in enumerate(axes[:, column]):
            ax.plot(t, q[:, joint], linewidth=1.0)
            for limit in (robot.q_min[3 + joint], robot.q_max[3 + joint]):
                ax.axhline(limit, color="green", linestyle="--", linewidth=1.0)
            ax.set_ylabel(f"{robot.joint_names[joint]} ({joint_unit(robot, joint)})")

        axes[-1, column].set_xlabel("t (s)")
    return figure


def _estimated(states: Sequence[Any]) -> list:
    """The states from the first valid one on: before its first fix the estimator's pose is
    a placeholder (0, 0), not where the robot was."""
    first = next((i for i, s in enumerate(states) if s.valid), len(states))
    return list(states[first:])


NO_FIX = "no valid state: the estimator never had a fix"


def _end_effector_path_figure(recordings: Sequence[_Recording], _: MobileManipulator) -> Figure:
    figure, axes = _panels(recordings, 1, 5.0)
    for ax, rec in zip(axes[0], recordings, strict=True):
        if estimated := _estimated(rec.states):
            _path(
                ax, [dq.translation(np.array(s.end_effector))[1:3] for s in estimated], "estimate"
            )
        else:
            _nothing(ax, NO_FIX)
        if rec.truth:
            truth = [dq.translation(np.array(s.end_effector))[1:3] for s in rec.truth]
            _path(ax, truth, "truth", linestyle="--")
        goals = np.array(
            [_goal_position(g)[:2] for g in rec.goals if g.task in END_EFFECTOR_TASKS]
        ).reshape(-1, 2)
        ax.plot(goals[:, 0], goals[:, 1], "*", color="green", markersize=12, label="goal")
        _legend(ax)
    return figure


def _base_path_figure(recordings: Sequence[_Recording], robot: MobileManipulator) -> Figure:
    from matplotlib.patches import Circle

    from analysis.floor_plan import draw_obstacles

    figure, axes = _panels(recordings, 1, 5.0)
    for ax, rec in zip(axes[0], recordings, strict=True):
        if estimated := _estimated(rec.states):
            _path(ax, [s.base_pose[:2] for s in estimated], "estimate")
            x, y = estimated[-1].base_pose[:2]
            ax.add_patch(
                Circle((x, y), robot.base.body_radius, fill=False, color="gray", label="base body")
            )
        else:
            _nothing(ax, NO_FIX)
        if rec.truth:
            _path(ax, [s.base_pose[:2] for s in rec.truth], "truth", linestyle="--")
        draw_obstacles(ax, rec.obstacles)
        ax.autoscale_view()
        _legend(ax)
    return figure


def _arm_clearance_figure(
    recordings: Sequence[_Recording], robot: MobileManipulator
) -> Figure | None:
    """Each collision part's clearance from the nearest solid over time, 0 (contact) dashed
    black; None when no session's truth has solids."""
    if all(rec.arm_clearance is None for rec in recordings):
        return None
    figure, axes = _panels(recordings, 1, 4.0, sharey=True)
    for ax, rec in zip(axes[0], recordings, strict=True):
        if rec.arm_clearance is None:
            _nothing(ax, "no solids in the ground truth")
            continue
        t, clearance = rec.arm_clearance
        for column, name in enumerate(robot.collision.names):
            ax.plot(t, clearance[:, column], label=name, linewidth=1.0)
        ax.axhline(0.0, color="black", linestyle="--", linewidth=1.0, label="contact")
        ax.set(xlabel="t (s)", ylabel="clearance from the nearest solid (m)")
        ax.legend(ncols=4, fontsize="small")
    return figure


def _path(ax: Axes, points: Sequence[Sequence[float]], label: str, **style: Any) -> None:
    """A path in the x-y plane from a circle at its start to a square at its end."""
    xy = np.array(points, dtype=float)
    (line,) = ax.plot(xy[:, 0], xy[:, 1], label=label, linewidth=1.2, **style)
    ax.plot(*xy[0], "o", color=line.get_color())
    ax.plot(*xy[-1], "s", color=line.get_color())
    ax.set(xlabel="x (m)", ylabel="y (m)", aspect="equal", adjustable="datalim")


_FIGURES: Mapping[str, Callable[[Sequence[_Recording], MobileManipulator], Figure | None]] = {
    "control_inputs.png": _control_inputs_figure,
    "nonzero_entries.png": _nonzero_figure,
    "error.png": _error_figure,
    "joints.png": _joints_figure,
    "end_effector_path.png": _end_effector_path_figure,
    "base_path.png": _base_path_figure,
    "arm_clearance.png": _arm_clearance_figure,
}
"""Every figure of the report, by file name (None: the sessions have nothing to draw in it)."""
