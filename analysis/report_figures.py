"""The figures of a report (section 6.2), drawn from checked sessions (``RecordedSession``).

Each figure draws one or two sessions side by side, a column each, titled by its label; a panel
with nothing to draw says why. ``FIGURES`` names them by file; ``analysis.report`` writes them.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from analysis.commands import Array
from messages.goal import Goal
from wbc import dq
from wbc.robot import MobileManipulator

if TYPE_CHECKING:  # matplotlib is imported by the first figure drawn, not by every command
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


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


@dataclass(frozen=True)
class RecordedSession:
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


PANEL_WIDTH_IN = 6.0
"""The width of each session's column, in."""
MARGINS_IN = (0.9, 0.25, 0.6, 0.4)
"""Left, right, bottom and top margins of a figure, in: room for the tick labels and axis labels
beside the panels and the titles above them. Fixed margins draw a report in about half the CPU
time matplotlib's constrained layout takes to find them."""
GAPS_IN = (0.9, 0.25)
"""Between two columns (the right one's axis label) and between two rows, in."""


def _panels(recordings: Sequence[RecordedSession], rows: int, height: float, **share: Any) -> tuple:
    """A figure with ``rows`` panels per session, sessions side by side, labels as titles."""
    from matplotlib.figure import Figure

    columns = len(recordings)
    width = PANEL_WIDTH_IN * columns
    (left, right, bottom, top), (across, down) = MARGINS_IN, GAPS_IN
    figure = Figure(figsize=(width, height))
    figure.subplots_adjust(
        left=left / width,
        right=1.0 - right / width,
        bottom=bottom / height,
        top=1.0 - top / height,
        wspace=across / ((width - left - right - across * (columns - 1)) / columns),
        hspace=down / ((height - bottom - top - down * (rows - 1)) / rows),
    )
    axes = figure.subplots(rows, columns, squeeze=False, **share)
    for ax, rec in zip(axes[0], recordings, strict=True):
        ax.set_title(rec.label)
    return figure, axes


def _control_inputs_figure(
    recordings: Sequence[RecordedSession], robot: MobileManipulator
) -> Figure:
    figure, axes = _panels(recordings, 1, 4.0, sharey=True)
    for ax, rec in zip(axes[0], recordings, strict=True):
        t = rec.command_seconds()
        for column, name in enumerate(input_names(robot)):
            ax.plot(t, rec.u[:, column], label=name, linewidth=1.0)
        ax.set(xlabel="t (s)", ylabel="u (m/s, rad/s)")
        ax.legend(ncols=4, fontsize="small")
    return figure


def _nonzero_figure(recordings: Sequence[RecordedSession], _: MobileManipulator) -> Figure:
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


def _error_figure(recordings: Sequence[RecordedSession], _: MobileManipulator) -> Figure:
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


def _task_error(rec: RecordedSession) -> tuple[Array, Array, tuple[str, ...]] | None:
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


def _joints_figure(recordings: Sequence[RecordedSession], robot: MobileManipulator) -> Figure:
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


def _end_effector_path_figure(
    recordings: Sequence[RecordedSession], _: MobileManipulator
) -> Figure:
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


def _base_path_figure(recordings: Sequence[RecordedSession], robot: MobileManipulator) -> Figure:
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
    recordings: Sequence[RecordedSession], robot: MobileManipulator
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


FIGURES: Mapping[str, Callable[[Sequence[RecordedSession], MobileManipulator], Figure | None]] = {
    "control_inputs.png": _control_inputs_figure,
    "nonzero_entries.png": _nonzero_figure,
    "error.png": _error_figure,
    "joints.png": _joints_figure,
    "end_effector_path.png": _end_effector_path_figure,
    "base_path.png": _base_path_figure,
    "arm_clearance.png": _arm_clearance_figure,
}
"""Every figure of the report, by file name (None: the sessions have nothing to draw in it)."""
