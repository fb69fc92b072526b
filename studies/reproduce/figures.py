"""The figures of `parsimony reproduce`: each pair of runs through the report's own figures
(``analysis.report``, as it draws a recording), the 2-norm and residual figure, and NOTES.md."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from analysis.report import write_report
from messages import topics
from messages.commands import ArmCommand, BaseCommand
from messages.diagnostics import ControllerDiagnostics
from messages.goal import Goal
from messages.header import Header
from messages.obstacles import Circle as CircleMessage
from messages.obstacles import Obstacles
from messages.state import RobotState
from studies.reproduce import laws as L
from studies.reproduce.dissertation import NOTES
from studies.reproduce.measures import residuals
from studies.reproduce.runs import Experiment
from wbc.geometry.scenarios import DT
from wbc.laws.kinematic_run import Run
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

PAIRS = {
    "pose": ("pose", (L.LP, L.CASCADE)),
    "pose/saturated": ("pose", (L.LP, L.SATURATED)),
    "pose/5.29": ("pose", (L.LP, L.LP_5_29)),
    "position": ("position", (L.LP, L.CASCADE)),
    "position/saturated": ("position", (L.LP, L.SATURATED)),
    "joint_limit": ("joint_limit", (L.LP, L.CASCADE)),
    "obstacle": ("obstacle", (L.LP, L.LP_BORDER)),
    "obstacle/5.29": ("obstacle", (L.LP_5_29,)),
}
"""Each folder of figures: the experiment and the one or two runs it draws."""


def write_figures(robot: MobileManipulator, found: dict[str, Experiment], out: Path) -> list[Path]:
    """Every folder of ``PAIRS``, the pose task's 2-norm and residual figure, and NOTES.md:
    what the dissertation's figures show, beside ours (of the experiments ``found``)."""
    written: list[Path] = []
    for folder, (name, labels) in PAIRS.items():
        if name not in found:
            continue
        experiment = found[name]
        sessions = [
            (label, session_of(experiment.runs[label], experiment, robot)) for label in labels
        ]
        written += write_report(sessions, robot, out / folder)["figures"]
    if "pose" in found:
        written.append(two_norm_figure(found["pose"], robot, out / "pose" / "two_norm.png"))
    lines = [
        "# Chapter 6 figures: what the dissertation shows, and ours",
        "",
        "| ours | the dissertation's |",
        "| --- | --- |",
    ]
    lines += [
        f"| `{path}` | {note} |" for path, note in NOTES.items() if path.split("/")[0] in found
    ]
    (out / "NOTES.md").write_text("\n".join(lines) + "\n")
    return [*written, out / "NOTES.md"]


def session_of(run: Run, experiment: Experiment, robot: MobileManipulator) -> dict[str, list]:
    """A kinematic run as the messages a recording of it would hold (stamps every DT), so the
    report draws it as it draws a recorded session."""

    def header(k: int, frame: str = "world") -> Header:
        return Header(stamp_ns=round(k * DT * 1e9), frame=frame, seq=k, source="reproduce")

    task = experiment.task
    goal = (
        Goal(header=header(0), task="pose", pose=tuple(task.pose.tolist()))
        if isinstance(task, PoseTask)
        else Goal(header=header(0), task="position", position=tuple(task.position.tolist()))
    )
    session: dict[str, list] = {
        topics.CONTROL_GOAL.name: [goal],
        topics.ROBOT_STATE.name: [],
        topics.BASE_COMMAND.name: [],
        topics.ARM_COMMAND.name: [],
        topics.CONTROL_DIAGNOSTICS.name: [],
    }
    if experiment.obstacles:
        circles = tuple(CircleMessage(x=c.x, y=c.y, radius=c.radius) for c in experiment.obstacles)
        session[topics.WORLD_OBSTACLES.name] = [Obstacles(header=header(0), circles=circles)]
    for k, (q, out) in enumerate(zip(run.configurations, run.outputs, strict=True)):
        session[topics.ROBOT_STATE.name].append(
            RobotState(
                header=header(k),
                base_pose=tuple(q[:3].tolist()),
                arm_joints=tuple(q[3:].tolist()),
                end_effector=tuple(robot.fkm(q).tolist()),
                valid=True,
                age_s=0.0,
            )
        )
        forward = float(out.u[0] * math.cos(q[2]) + out.u[1] * math.sin(q[2]))
        session[topics.BASE_COMMAND.name].append(
            BaseCommand(
                header=header(k, "base"),
                forward_velocity=forward,
                angular_velocity=float(out.u[2]),
                left_wheel=0.0,
                right_wheel=0.0,
            )
        )
        session[topics.ARM_COMMAND.name].append(
            ArmCommand(header=header(k, "arm"), joint_velocities=tuple(out.u[3:].tolist()))
        )
        session[topics.CONTROL_DIAGNOSTICS.name].append(
            ControllerDiagnostics(
                header=header(k),
                law="reproduce",
                status=out.status,
                nonzero=out.nonzero,
                practical_nonzero=out.practical_nonzero,
                solve_time_us=out.solve_time_s * 1e6,
                error_norm=out.error_norm,
            )
        )
    return session


def two_norm_figure(pose: Experiment, robot: MobileManipulator, path: Path) -> Path:
    """Above, ||u||_2 of each step of the pose runs (table 6.1's metric 2 integrates its
    square); below, each step's ||J u + eta e|| / ||eta e||, 0 where u realises J u = -eta e
    (the rows ``pose.residual.*`` give its first, median and largest value)."""
    figure = Figure(figsize=(8.0, 7.0), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    for label in (L.LP, L.LP_5_29, L.CASCADE, L.SATURATED, L.LP_FREE, L.PINV_5_11):
        run = pose.runs[label]
        t = np.arange(len(run.outputs)) * DT
        top.plot(t, [np.linalg.norm(out.u) for out in run.outputs], label=label)
        bottom.plot(t, residuals(run, robot, pose.task, pose.eta), label=label)
    top.set(
        ylabel="||u||_2",
        xlim=(0.0, 6.0),
        title="pose task: the 2-norm of u (metric 2) and the residual of J u = -eta e",
    )
    bottom.set(xlabel="t (s)", ylabel="||J u + eta e|| / ||eta e||", yscale="log")
    top.legend(fontsize="small")
    figure.savefig(path, dpi=100)
    return path
