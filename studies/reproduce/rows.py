"""The rows of section 6.2 and table 6.1: each law's figures beside the dissertation's, from
the runs of ``studies.reproduce.runs``."""

from __future__ import annotations

from dataclasses import astuple

from studies.goal_sets import MOVING_ERROR, SETTLING_S
from studies.reproduce import laws as L
from studies.reproduce import measures as M
from studies.reproduce.dissertation import (
    ABRUPT,
    CONTRADICTED,
    ENTRIES,
    EXPECTED,
    PERIOD_MS,
    TABLE_6_1,
)
from studies.reproduce.runs import Experiment
from studies.reproduce.table import Row
from wbc.geometry.scenarios import OBSTACLE, OBSTACLE_GOAL
from wbc.laws.kinematic_run import control_effort
from wbc.robot import MobileManipulator

MAIN = (L.LP, L.LP_5_29, L.CASCADE, L.SATURATED)
"""The laws of every row of 6.2: the default LP beside 5.29 as written, the cascade as the
dissertation ran it beside the cascade held to the robot's bounds."""
SECTION = {"pose": "6.2.1", "position": "6.2.2"}
FIGURES = {"pose": ("fig. 6.7", "fig. 6.8"), "position": ("fig. 6.12", "fig. 6.13")}
PHASES = f"[of u, x' y' as one] while ||e|| > {MOVING_ERROR}; over the last {SETTLING_S:g} s"


def side(label: str) -> str:
    """Which of the dissertation's two laws ``label`` stands for."""
    return "LP" if label.startswith(("LP", "QP")) else "PINV"


def present(labels: tuple[str, ...], runs: dict) -> tuple[str, ...]:
    """Those of ``labels`` that ran (a run on the loop runs fewer laws)."""
    return tuple(label for label in labels if label in runs)


def task_rows(robot: MobileManipulator, experiment: Experiment) -> list[Row]:
    """Sections 6.2.1 and 6.2.2 for one task: convergence, nonzero entries under one rule,
    abruptness, the residual of J u = -eta e, the first step, the bounds u meets, and on the
    position task figure 6.14's path."""
    name, runs, section = experiment.name, experiment.runs, SECTION[experiment.name]
    exact, practical = FIGURES[name]
    main = present(MAIN, runs)
    out = [
        Row(
            f"{name}.converged",
            section,
            f"{name} task: converged, iterations to {experiment.until}",
            "both converge",
            {label: [runs[label].converged, len(runs[label].outputs)] for label in main},
            experiment=name,
            laws=main,
        )
    ]
    for label in main:
        run = runs[label]
        out += [
            Row(
                f"{name}.entries.{label}",
                section,
                f"{label}: {exact}, median nonzero entries {PHASES}",
                ENTRIES[name][side(label)],
                M.entry_counts(run),
                experiment=name,
                laws=(label,),
            ),
            Row(
                f"{name}.practical.{label}",
                section,
                f"{label}: {practical}, the same with |u_i| >= Upsilon 0.01",
                f"fewer than in {exact}",
                M.entry_counts(run, practical=True),
                experiment=name,
                laws=(label,),
            ),
            Row(
                f"{name}.abrupt.{label}",
                section,
                f"{label}: how abrupt u is: sum of "
                "||u_k+1 - u_k||_1 (metric 3), largest jump of one entry in a step, switches "
                "of the set of nonzero entries",
                ABRUPT[name],
                M.abruptness(run),
                "LP above PINV",
                experiment=name,
                laws=(label,),
            ),
        ]
    first = main[0]  # every kinematic run starts at HOME
    start, task = runs[first].configurations[0], experiment.step_tasks(first)
    task = task[0] if isinstance(task, list) else task
    out.append(
        Row(
            f"{name}.least_residual",
            section,
            "||J u + eta e|| / ||eta e|| no u can "
            "beat at the start (e outside the range of J; of J N under 5.11)",
            "not given",
            {
                "any u": M.least_residual(robot, task, start, False),
                "under 5.11": M.least_residual(robot, task, start, True),
            },
            experiment=name,
        )
    )
    for label in present((*MAIN, L.LP_FREE, L.PINV_5_11), runs):
        run = runs[label]
        residual = M.residuals(run, robot, experiment.step_tasks(label), experiment.eta)
        out += [
            Row(
                f"{name}.residual.{label}",
                section,
                f"{label}: ||J u + eta e|| / ||eta e|| at the first step, median, largest",
                "not given",
                [residual[0], M.median(residual), max(residual)],
                "0: u realises J u = -eta e",
                experiment=name,
                laws=(label,),
            ),
            Row(
                f"{name}.first_step.{label}",
                section,
                f"{label}: u at the first step, ||u||_2, the rows that bind",
                "not given",
                M.first_step(run),
                experiment=name,
                laws=(label,),
            ),
            Row(
                f"{name}.speeds.{label}",
                section,
                f"{label}: steps beyond a bound (LP's or "
                "wheels'), steps on a speed bound and on a bound of 5.15 by entry, peaks, "
                "heading range (rad)",
                "not given",
                M.speeds(run, robot),
                "0 beyond a bound",
                experiment=name,
                laws=(label,),
            ),
        ]
    if name == "position":
        out += [
            Row(
                f"position.path.{label}",
                section,
                f"{label}: fig. 6.14, the end "
                "effector's path against the straight line to the goal",
                "settles very close to the goal",
                M.end_effector_path(experiment.true_run(label), robot, experiment.task.position),
                experiment=name,
                laws=(label,),
            )
            for label in main
        ]
    return out


def joint_limit_rows(robot: MobileManipulator, experiment: Experiment) -> list[Row]:
    """Figure 6.10: how far each law takes an arm joint beyond its limit."""
    return [
        Row(
            f"joint_limit.{label}",
            "6.2.1",
            f"{label}: fig. 6.10, largest excursion beyond an arm joint's limit (rad), the joint",
            "LP 0" if side(label) == "LP" else "PINV past q8's",
            M.worst_overrun(run, robot),
            "LP 0, PINV > 0",
            experiment=experiment.name,
            laws=(label,),
        )
        for label, run in experiment.runs.items()
    ]


def obstacle_rows(robot: MobileManipulator, experiment: Experiment) -> list[Row]:
    """Section 6.2.3: going round the obstacle (fig. 6.16) and the entries (fig. 6.17)."""
    out = []
    for label, run in experiment.runs.items():
        goal = OBSTACLE_GOAL[:2]
        out += [
            Row(
                f"obstacle.round.{label}",
                "6.2.3",
                f"{label}: fig. 6.16, converged, final ||e||, the base round the obstacle",
                "round it, no contact, stabilised near the goal",
                {
                    "converged": run.converged,
                    "final ||e||": run.final_error,
                    **M.round_obstacle(experiment.true_run(label), robot, OBSTACLE, goal),
                },
                "clearance > 0, passed it",
                experiment="obstacle",
                laws=(label,),
            ),
            Row(
                f"obstacle.entries.{label}",
                "6.2.3",
                f"{label}: fig. 6.17, median nonzero "
                "entries [of u, x' y' as one] over the run and while an obstacle row binds",
                ENTRIES["obstacle"]["LP"],
                M.obstacle_entries(run),
                experiment="obstacle",
                laws=(label,),
            ),
        ]
    return out


COMPARISONS = (
    (L.LP, L.CASCADE, "as the dissertation ran it"),
    (L.LP, L.SATURATED, "the cascade held to the robot's bounds"),
    (L.LP_5_29, L.CASCADE, "5.29 as written, the cascade as run"),
    (L.LP_5_29, L.SATURATED, "5.29 as written, the cascade held to the bounds"),
    (L.LP, L.CASCADE_LP_TIME, "the cascade converging in the LP's time"),
    (L.LP_FREE, L.PINV_5_11, "neither bounded, both under 5.11"),
)
"""Table 6.1's comparisons: LP / PINV of each metric, as the dissertation ran it and others."""


def effort_rows(experiment: Experiment) -> list[Row]:
    """Table 6.1 for one task: the four metrics of each law (after the iterations it took),
    then the ratio LP / PINV of each metric in each of the COMPARISONS."""
    name = experiment.name
    theirs = TABLE_6_1[name]
    metrics = {label: list(astuple(control_effort(run))) for label, run in experiment.runs.items()}
    out = [
        Row(
            f"{name}.metrics.{label}",
            "table 6.1",
            f"{name}: {label}, metrics 1-4, after {len(experiment.runs[label].outputs)} iterations",
            list(theirs[side(label)]),
            metrics[label],
            experiment=name,
            laws=(label,),
        )
        for label in present((*MAIN, L.CASCADE_LP_TIME, L.LP_FREE, L.PINV_5_11), experiment.runs)
    ]
    ratios = [lp / pinv for lp, pinv in zip(theirs["LP"], theirs["PINV"], strict=True)]
    direction = ", ".join(CONTRADICTED.get((name, i), e) for i, e in enumerate(EXPECTED))
    for lp, pinv, what in COMPARISONS:
        if not (lp in metrics and pinv in metrics):
            continue
        out.append(
            Row(
                f"{name}.ratio.{lp}/{pinv}",
                "table 6.1",
                f"{name}: {lp} / {pinv}, metrics 1-4 ({what})",
                ratios,
                [a / b for a, b in zip(metrics[lp], metrics[pinv], strict=True)],
                direction,
                experiment=name,
                laws=(lp, pinv),
            )
        )
    return out


def step_time_rows(found: dict[str, Experiment]) -> list[Row]:
    """Section 6.3's "each iteration under 20 ms", on the law's own step in this process: of
    each law that ran the pose and the position task (of those ``found``)."""
    names = [name for name in ("pose", "position") if name in found]
    labels = [label for label in MAIN if all(label in found[n].runs for n in names)]
    return [
        Row(
            f"step_time.{label}",
            "6.3",
            f"{label}: the law's step (model, Jacobian, rows, "
            f"solve; not the loop's messages) over the {' and '.join(names)} runs, ms",
            f"under {PERIOD_MS:g} ms",
            M.step_times_ms([found[n].runs[label] for n in names]),
            f"p99 < {PERIOD_MS:g}",
            ", ".join(names),
            (label,),
            timed=True,
        )
        for label in labels
        if names
    ]
