"""`parsimony reproduce`: every result of chapter 6, the dissertation's beside ours.

The set-ups of chapter 6 run kinematically (q += u dt at 50 Hz, on the robot of deploy/robots,
from ``wbc.scenarios.HOME``) with the dissertation's gains: 6.2.1 (pose, eta 0.6, beta 15, k 1,
b_l 0.9), 6.2.2 (position, eta 1, beta 10), 6.2.3 (obstacle), the joint limit of figure 6.10,
table 6.1 and the convergence test of 6.3 (``parsimony.benchmark.convergence_test``). "PINV" of
6.2 is the classic law for this robot: the cascade of appendix B. Each row gives what the
dissertation reports, what this run gives and the direction the comparison should take (from
the dissertation's text); the command makes no judgement. ``write_figures`` draws the runs with
the report's own figures (``record.report``) and a note of what the dissertation's show.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from messages.commands import ArmCommand, BaseCommand
from messages.diagnostics import ControllerDiagnostics
from messages.goal import Goal
from messages.header import Header
from messages.obstacles import Circle as CircleMessage
from messages.obstacles import Obstacles
from messages.state import RobotState
from parsimony.benchmark import UNBOUNDED_SPEED, convergence_test
from parsimony.goal_sets import MOVING_ERROR, SETTLING_S
from parsimony.kinematic_demo import BORDER_PARAMS, LP_PARAMS, input_change_gains
from parsimony.output import table
from record.report import write_report
from wbc import dq
from wbc.cascade_law import CascadeLaw, CascadeParams
from wbc.kinematic_run import Run, control_effort, integrate
from wbc.law_output import Law, entry_mask
from wbc.lp_law import LPLaw
from wbc.pinv_law import PINV_RCOND, PinvParams, PseudoinverseLaw, nonholonomic_basis
from wbc.qp_law import QPLaw, QPParams
from wbc.robot import MobileManipulator
from wbc.scenarios import DT, HOME, JOINT_LIMIT_GOAL, OBSTACLE, OBSTACLE_GOAL, REACH_GOAL
from wbc.task import PoseTask, PositionTask, Task

STEPS = 4000
METRICS = ("velocity_l1", "velocity_l2", "acceleration_l1", "acceleration_l2")
TABLE_6_1 = {
    "pose": {"PINV": (1.9796, 0.2960, 0.0026, 0.00013), "LP": (1.4944, 0.3267, 0.0012, 0.00004)},
    "position": {"PINV": (0.3907, 0.0583, 0.0047, 0.00084),
                 "LP": (0.3431, 0.0654, 0.0021, 0.00085)},
}  # fmt: skip
"""Table 6.1: metrics 1..4 of each law in the pose and the position experiment."""
EXPECTED = ("LP lower (1-norm)", "PINV lower (2-norm)", "LP lower (1-norm)", "PINV lower (2-norm)")
"""What section 6.2.1 says each metric should show: the 1-norm metrics favour the LP, the
2-norm ones the classic law."""
SECTION_6_3 = {
    "holonomic": {"iterations": 46, "classic_ms": 158.96 / 46, "lp_ms": 173.42 / 46},
    "nonholonomic": {"iterations": 77, "classic_ms": 251.03 / 77, "lp_ms": 290.14 / 77},
}
"""Section 6.3: iterations to ||e|| < 1e-3 (the same for both laws) and ms per iteration (the
average convergence time over the iterations: 3.4 ms and 3.7 ms in figure 6.20)."""
NOTES = {
    "pose/control_inputs.png": "fig. 6.6: the LP's inputs more abrupt than PINV's",
    "pose/nonzero_entries.png": "figs. 6.7, 6.8: LP 7 entries while moving and 6 after the "
                                "150th iteration, fewer in practice (Upsilon 0.01); PINV all 8",
    "pose/error.png": "fig. 6.9: every coefficient of e converges, the LP's less smoothly",
    "pose/joints.png": "fig. 6.10: the LP inside every joint limit",
    "joint_limit/joints.png": "fig. 6.10: PINV past a joint's limit (q8 there), the LP inside",
    "position/control_inputs.png": "fig. 6.11: the LP's inputs more abrupt",
    "position/nonzero_entries.png": "figs. 6.12, 6.13: LP five entries most of the time; PINV 8",
    "position/end_effector_path.png": "fig. 6.14: both end effectors settle on the goal",
    "obstacle/nonzero_entries.png": "fig. 6.17: the LP uses all 8 entries most of the time",
    "obstacle/base_path.png": "fig. 6.16: the base goes round the obstacle",
    "pose/two_norm.png": "not in the dissertation: why metric 2 goes the LP's way here",
}  # fmt: skip
"""What each of the dissertation's figures shows, beside the file of ours that draws it."""


@dataclass(frozen=True)
class Row:
    """One result: the dissertation's value, ours, and which way the comparison should go."""

    section: str
    result: str
    dissertation: Any
    ours: Any
    direction: str = ""


@dataclass(frozen=True)
class Experiment:
    """A set-up of chapter 6 and the runs of its laws."""

    name: str
    task: Task
    runs: dict[str, Run]
    obstacles: tuple = ()


def run_laws(name: str, task: Task, laws: dict[str, Law], obstacles: tuple = ()) -> Experiment:
    return Experiment(name, task, {label: integrate(law, HOME, task, DT, STEPS,
                                                    obstacles=obstacles)
                                   for label, law in laws.items()}, obstacles)  # fmt: skip


def experiments(robot: MobileManipulator) -> dict[str, Experiment]:
    """The set-ups of 6.2 with their laws: the LP and the cascade as the dissertation ran them
    (the cascade's eta that of the LP); for table 6.1, the cascade with the eta that converges
    in the LP's time, and two laws that both realise J u = -eta e at every step: the LP
    without speed bounds (the cascade has none) and the pseudoinverse under 5.11."""
    free = robot.with_velocity_max(np.full(robot.dof, UNBOUNDED_SPEED))
    reach = robot.fkm(REACH_GOAL)
    tasks = {"pose": PoseTask(reach), "position": PositionTask(dq.translation(reach)[1:])}
    found = {}
    for name, task in tasks.items():
        params = LP_PARAMS[name]
        found[name] = run_laws(name, task, {
            "LP": LPLaw(robot, params),
            "PINV": CascadeLaw(robot, CascadeParams(eta=params.eta)),
            "LP, no speed bound": LPLaw(free, params),
            "PINV under 5.11": PseudoinverseLaw(robot, PinvParams(eta=params.eta,
                                                                  nonholonomic=True)),
            "QP": QPLaw(robot, QPParams(eta=params.eta, beta=params.beta)),
            WITH_INPUT_CHANGE: LPLaw(robot, replace(params, **input_change_gains())),
        })  # fmt: skip
        eta = matched_eta(robot, task, len(found[name].runs["LP"].outputs))
        found[name].runs["PINV, same time"] = integrate(
            CascadeLaw(robot, CascadeParams(eta=eta)), HOME, task, DT, STEPS)
    found["obstacle"] = run_laws("obstacle", PoseTask(robot.fkm(OBSTACLE_GOAL)), {
        "LP": LPLaw(robot, LP_PARAMS["obstacle"]), "LP 5.28": LPLaw(robot, BORDER_PARAMS)},
        (OBSTACLE,))  # fmt: skip
    found["joint_limit"] = run_laws("joint_limit", PoseTask(robot.fkm(JOINT_LIMIT_GOAL)), {
        "LP": LPLaw(robot, LP_PARAMS["pose"]), "PINV": CascadeLaw(robot)})  # fmt: skip
    return found


COMPARISONS = {
    "": ("LP", "PINV"),
    ", cascade converging in the LP's time": ("LP", "PINV, same time"),
    ", both meeting J u = -eta e (LP with no speed bound, PINV under 5.11)":
        ("LP, no speed bound", "PINV under 5.11"),
}  # fmt: skip
"""Table 6.1's comparisons: as the dissertation ran them, then two fairer ones."""


def matched_eta(robot: MobileManipulator, task: Task, steps: int) -> float:
    """The cascade's eta that converges in ``steps`` (bisection on eta in [0.3, 3], to 1 %):
    the dissertation tuned both laws "for a fast and smooth convergence"."""
    low, high = 0.3, 3.0
    while high / low > 1.01:
        eta = math.sqrt(low * high)
        taken = len(integrate(CascadeLaw(robot, CascadeParams(eta=eta)), HOME, task, DT,
                              STEPS).outputs)  # fmt: skip
        low, high = (eta, high) if taken > steps else (low, eta)
    return math.sqrt(low * high)


def counts(run: Run, practical: bool = False) -> dict[str, float]:
    """Median nonzero entries of u while moving (||e|| > MOVING_ERROR), over the last
    SETTLING_S, and over the last SETTLING_S with x' and y' as one entry."""
    masks = [entry_mask(out.u, practical) for out in run.outputs]
    moving = [m.bit_count() for m, o in zip(masks, run.outputs, strict=True)
              if o.error_norm > MOVING_ERROR]  # fmt: skip
    last = masks[-round(SETTLING_S / DT):]

    def median(values: list[int]) -> float:
        return float(np.median(values)) if values else math.nan

    return {"moving": median(moving), "settling": median([m.bit_count() for m in last]),
            "settling_forward_as_one": median([m.bit_count() - (m & 3 == 3) for m in last])}


def worst_overrun(run: Run, robot: MobileManipulator) -> tuple[float, int]:
    """The largest excursion of an arm joint beyond its limit (rad, 0 inside), and which
    entry of q (1-based, as q8 in figure 6.10)."""
    q = np.array(run.configurations)
    beyond = np.maximum(q - robot.q_max, robot.q_min - q).max(axis=0)
    entry = int(np.argmax(beyond))
    return float(max(beyond[entry], 0.0)), entry + 1


def rows(robot: MobileManipulator, found: dict[str, Experiment]) -> list[Row]:
    """Every comparison of section 6.2 and table 6.1, from the runs in ``found``."""
    pose, position = found["pose"], found["position"]
    out = [
        Row("6.2.1", "pose task: converged (LP, PINV)", "both",
            [pose.runs["LP"].converged, pose.runs["PINV"].converged]),
        Row("6.2.1", "pose task: iterations to ||e|| < 1e-3 (LP, PINV)", "not given",
            [len(pose.runs["LP"].outputs), len(pose.runs["PINV"].outputs)]),
    ]
    out += count_rows("6.2.1", "fig. 6.7", "fig. 6.8", pose, moving=7, settling=6, pinv=8)
    overrun = {label: worst_overrun(run, robot) for label, run in found["joint_limit"].runs.items()}
    out.append(Row("6.2.1", "fig. 6.10: largest excursion beyond a joint limit, rad (LP, PINV); "
                   "the joint", "LP 0, PINV past q8's",
                   [overrun["LP"][0], overrun["PINV"][0], f"q{overrun['PINV'][1]}"],
                   "LP 0, PINV > 0"))
    out.append(Row("6.2.2", "position task: converged (LP, PINV)", "both",
                   [position.runs["LP"].converged, position.runs["PINV"].converged]))
    out += count_rows("6.2.2", "fig. 6.12", "fig. 6.13", position, moving=5, settling=5, pinv=8)
    for experiment in (pose, position):
        out += effort_rows(experiment)
    for experiment in (pose, position):
        out += qp_rows(experiment)
    for experiment in (pose, position):
        out += input_change_rows(experiment)
    for label, run in found["obstacle"].runs.items():
        q = np.array(run.configurations)
        gap = np.hypot(q[:, 0] - OBSTACLE.x, q[:, 1] - OBSTACLE.y) - OBSTACLE.radius
        constraint = "5.28" if label == "LP 5.28" else "the vector-field inequality"
        out += [
            Row("6.2.3", f"obstacle, {constraint}: converged, least clearance of the base body, "
                "m", "yes, no contact", [run.converged, float(gap.min() -
                                                                robot.base.body_radius)],
                "clearance > 0"),
            Row("6.2.3", f"fig. 6.17, {constraint}: median nonzero entries of u", 8,
                float(np.median([o.nonzero for o in run.outputs]))),
        ]  # fmt: skip
    return out


def count_rows(section: str, exact: str, practical: str, experiment: Experiment, moving: int,
               settling: int, pinv: int) -> list[Row]:  # fmt: skip
    """Figures 6.7 and 6.8 (or 6.12 and 6.13): the medians the dissertation's curves show."""
    lp, _classic = counts(experiment.runs["LP"]), counts(experiment.runs["PINV"])
    used = counts(experiment.runs["LP"], practical=True)
    used_classic = counts(experiment.runs["PINV"], practical=True)
    return [
        Row(section, f"{exact}: median nonzero entries of u, LP, while ||e|| > {MOVING_ERROR}",
            moving, lp["moving"], f"<= {moving}"),
        Row(section, f"{exact}: LP, last {SETTLING_S:g} s (x', y' as one entry)", settling,
            [lp["settling"], lp["settling_forward_as_one"]], f"<= {settling}"),
        Row(section, f"{exact}: PINV, every step", pinv,
            float(np.median([o.nonzero for o in experiment.runs["PINV"].outputs]))),
        Row(section, f"{practical}: practical entries (Upsilon 0.01), LP and PINV, while moving",
            "fewer than in " + exact, [used["moving"], used_classic["moving"]]),
    ]


def effort_rows(experiment: Experiment) -> list[Row]:
    """Table 6.1 for one task: each metric, LP against PINV and the ratio LP / PINV, theirs
    beside ours in each of the COMPARISONS, after the iterations each run took."""
    table = TABLE_6_1[experiment.name]
    efforts = {label: asdict(control_effort(run)) for label, run in experiment.runs.items()}
    out = [Row("table 6.1", f"{experiment.name}: iterations of each run", "not given",
               {label: len(run.outputs) for label, run in experiment.runs.items()})]
    for suffix, (lp, pinv) in COMPARISONS.items():
        for index, metric in enumerate(METRICS):
            theirs = {"LP": table["LP"][index], "PINV": table["PINV"][index]}
            ours = {"LP": efforts[lp][metric], "PINV": efforts[pinv][metric]}
            out.append(Row("table 6.1", f"{experiment.name}, metric {index + 1}{suffix}",
                           {**theirs, "LP/PINV": theirs["LP"] / theirs["PINV"]},
                           {**ours, "LP/PINV": ours["LP"] / ours["PINV"]}, EXPECTED[index]))
    return out


def qp_rows(experiment: Experiment) -> list[Row]:
    """Future work 5 (7.2): the LP against the QP of the same rows and terms, on one run each:
    iterations, nonzero entries while moving, and table 6.1's four metrics."""
    lp, qp = experiment.runs["LP"], experiment.runs["QP"]
    efforts = {label: asdict(control_effort(run)) for label, run in (("LP", lp), ("QP", qp))}
    out = [Row("7.2 (5)", f"{experiment.name}: LP against QP, iterations; nonzero entries "
                          "while moving", "not done",
               {"LP": [len(lp.outputs), counts(lp)["moving"]],
                "QP": [len(qp.outputs), counts(qp)["moving"]]}, "LP sparser")]  # fmt: skip
    for index, metric in enumerate(METRICS):
        out.append(Row("7.2 (5)", f"{experiment.name}: LP against QP, metric {index + 1}",
                       "not done", {"LP": efforts["LP"][metric], "QP": efforts["QP"][metric],
                                    "LP/QP": efforts["LP"][metric] / efforts["QP"][metric]}))
    return out


WITH_INPUT_CHANGE = "LP with the input change term"
"""The LP of each task with the input change term of deploy/sim_smooth.yaml on."""


def input_change_rows(experiment: Experiment) -> list[Row]:
    """Future work 1 (7.2): the LP with its input change term against the LP, on one run each:
    iterations, nonzero entries (while moving, last 2 s) and table 6.1's metrics as it takes
    them, then 3 and 4 from rest (u = 0 before the first command, as in a recording)."""
    runs = {"with": experiment.runs[WITH_INPUT_CHANGE], "LP": experiment.runs["LP"]}
    title = f"{experiment.name}: LP with the input change term against without"
    nonzero = {label: counts(run) for label, run in runs.items()}
    out = [Row("7.2 (1)", f"{title}, iterations; nonzero entries while moving, last 2 s",
               "not done", {label: [len(run.outputs), nonzero[label]["moving"],
                                    nonzero[label]["settling"]] for label, run in runs.items()},
               "the same entries")]  # fmt: skip
    efforts = {(label, from_rest): control_effort(run, from_rest)
               for label, run in runs.items() for from_rest in (False, True)}  # fmt: skip
    measures = [(index, metric, False) for index, metric in enumerate(METRICS)]
    measures += [(index, METRICS[index], True) for index in (2, 3)]
    for index, metric, from_rest in measures:
        values = {label: getattr(efforts[label, from_rest], metric) for label in runs}
        out.append(Row("7.2 (1)", f"{title}, metric {index + 1}{' from rest' * from_rest}",
                       "not done", {**values, "with/LP": values["with"] / values["LP"]},
                       "with lower" if index >= 2 else ""))  # fmt: skip
    return out


def convergence_rows(test: dict[str, dict[str, float]]) -> list[Row]:
    out = []
    for kind, theirs in SECTION_6_3.items():
        classic = test[f"{kind}/{'classic' if kind == 'holonomic' else 'cascade'}"]
        lp = test[f"{kind}/lp"]
        out += [
            Row("6.3", f"test {1 if kind == 'holonomic' else 2} ({kind}): iterations to 1e-3 "
                "(classic, LP)", theirs["iterations"], [classic["iterations"], lp["iterations"]],
                "the same for both"),
            Row("6.3", f"test {1 if kind == 'holonomic' else 2}: ms per iteration (classic, LP)",
                [round(theirs["classic_ms"], 2), round(theirs["lp_ms"], 2)],
                [classic["time_per_iteration_us"] / 1e3, lp["time_per_iteration_us"] / 1e3],
                "classic faster"),
        ]  # fmt: skip
    return out


def reproduce(robot: MobileManipulator, trials: int = 20) -> tuple[list[Row], dict]:
    """The rows, and the experiments they come from. The timed test of 6.3 runs first, before
    thousands of runs' outputs load the garbage collector."""
    test = convergence_test(robot, trials)
    found = experiments(robot)
    return rows(robot, found) + convergence_rows(test), found


def write_figures(robot: MobileManipulator, found: dict[str, Experiment], out: Path) -> list[Path]:
    """Each experiment's runs through the report's figures (LP beside PINV), the metric-2
    figure, and NOTES.md: what the dissertation's figures show, beside ours."""
    written: list[Path] = []
    for name, experiment in found.items():
        labels = [label for label in ("LP", "PINV", "LP 5.28") if label in experiment.runs]
        sessions = [(label, session_of(experiment.runs[label], experiment, robot))
                    for label in labels]  # fmt: skip
        written += write_report(sessions, robot, out / name)["figures"]
    written.append(two_norm_figure(found["pose"], robot, out / "pose" / "two_norm.png"))
    lines = ["# Chapter 6 figures: what the dissertation shows, and ours", "",
             "| ours | the dissertation's |", "| --- | --- |"]  # fmt: skip
    lines += [f"| `{path}` | {note} |" for path, note in NOTES.items()]
    (out / "NOTES.md").write_text("\n".join(lines) + "\n")
    return [*written, out / "NOTES.md"]


def session_of(run: Run, experiment: Experiment, robot: MobileManipulator) -> dict[str, list]:
    """A kinematic run as the messages a recording of it would hold (stamps every DT), so the
    report draws it as it draws a recorded session."""
    def header(k: int, frame: str = "world") -> Header:
        return Header(stamp_ns=round(k * DT * 1e9), frame=frame, seq=k, source="reproduce")

    task = experiment.task
    goal = (Goal(header=header(0), task="pose", pose=tuple(task.pose.tolist()))
            if isinstance(task, PoseTask) else
            Goal(header=header(0), task="position", position=tuple(task.position.tolist())))
    session: dict[str, list] = {"control/goal": [goal], "robot/state": [], "base/command": [],
                                "arm/command": [], "control/diagnostics": []}  # fmt: skip
    if experiment.obstacles:
        circles = tuple(CircleMessage(x=c.x, y=c.y, radius=c.radius) for c in experiment.obstacles)
        session["world/obstacles"] = [Obstacles(header=header(0), circles=circles)]
    for k, (q, out) in enumerate(zip(run.configurations, run.outputs, strict=True)):
        session["robot/state"].append(RobotState(
            header=header(k), base_pose=tuple(q[:3].tolist()), arm_joints=tuple(q[3:].tolist()),
            end_effector=tuple(robot.fkm(q).tolist()), valid=True, age_s=0.0))
        forward = float(out.u[0] * math.cos(q[2]) + out.u[1] * math.sin(q[2]))
        session["base/command"].append(BaseCommand(
            header=header(k, "base"), forward_velocity=forward, angular_velocity=float(out.u[2]),
            left_wheel=0.0, right_wheel=0.0))
        session["arm/command"].append(ArmCommand(header=header(k, "arm"),
                                                 joint_velocities=tuple(out.u[3:].tolist())))
        session["control/diagnostics"].append(ControllerDiagnostics(
            header=header(k), law="reproduce", status=out.status, nonzero=out.nonzero,
            practical_nonzero=out.practical_nonzero, solve_time_us=out.solve_time_s * 1e6,
            error_norm=out.error_norm))
    return session  # fmt: skip


def two_norm_figure(pose: Experiment, robot: MobileManipulator, path: Path) -> Path:
    """||u||_2 of each step of the pose runs, and for the LPs the least ||u||_2 that gives the
    same J u under 5.11 (the pseudoinverse of J N). Metric 2 integrates ||u||_2^2 along each
    law's own trajectory: the LP is bounded at 0.8 rad/s and asks the task for less at the
    start than the cascade, which has no bound; and without the bound, the LP still ends
    lower than the pseudoinverse under 5.11, though at every step it lies above the least
    2-norm of its own J u: the two trajectories pass through other configurations."""
    figure = Figure(figsize=(8.0, 4.5), layout="constrained")
    ax = figure.subplots()
    for label, run in pose.runs.items():
        t = np.arange(len(run.outputs)) * DT
        (line,) = ax.plot(t, [np.linalg.norm(out.u) for out in run.outputs], label=label)
        if label.startswith("LP"):
            least = [least_two_norm(robot, pose.task, q, out.u)
                     for q, out in zip(run.configurations, run.outputs, strict=True)]  # fmt: skip
            ax.plot(t, least, linestyle="--", color=line.get_color(),
                    label=f"{label}: least ||u||_2 with its J u under 5.11")
    ax.set(xlabel="t (s)", ylabel="||u||_2", xlim=(0.0, 6.0),
           title="pose task: the 2-norm of u, table 6.1's metric 2")
    ax.legend(fontsize="small")
    figure.savefig(path, dpi=100)
    return path


def least_two_norm(robot: MobileManipulator, task: Task, q: np.ndarray, u: np.ndarray) -> float:
    """min ||u'||_2 over u' with J u' = J u and 5.11: ||(J N)^+ J u|| (N orthonormal)."""
    pose, jacobian = robot.kinematics(q)
    _, task_jacobian = task.error(pose, jacobian, q)
    basis = nonholonomic_basis(float(q[2]), robot.dof)
    nu = np.linalg.pinv(task_jacobian @ basis, rcond=PINV_RCOND) @ (task_jacobian @ u)
    return float(np.linalg.norm(nu))


def format_rows(found_rows: list[Row]) -> str:
    def shown(value: Any) -> str:
        if isinstance(value, list):
            return ", ".join(shown(v) for v in value)
        if isinstance(value, dict):
            return ", ".join(f"{k} {shown(v)}" for k, v in value.items())
        if isinstance(value, float):
            return f"{value:.4g}"
        return str(value)

    return table([(r.section, r.result, shown(r.dissertation), shown(r.ours), r.direction)
                  for r in found_rows],
                 ("section", "result", "dissertation", "ours", "should be"),
                 disable_numparse=True)  # fmt: skip

