"""`parsimony bench`: what one control step costs (on Little John and on every robot of the
zoo, studies.step_timing), the convergence test of section 6.3, goal shares. Every figure comes
from one run on this machine.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from outputs.stdout import table
from profiles import deploy_files
from profiles.deploy_files import ROBOT_FILE
from studies.gain_sets import TABLE_PARAMS, WITHOUT_ARM_ROWS
from studies.goal_report import goal_report
from studies.reproduce import efficiency
from studies.step_timing import (
    blocks,
    lp_breakdown,
    percentiles,
    step_times,
    time_calls,
    zoo_step_times,
)
from wbc import dq
from wbc.geometry.scenarios import (
    DT,
    HOME,
    REACH_GOAL,
    TABLE,
    TABLE_GOAL,
    TABLE_START,
)
from wbc.laws.constraints.arm_obstacles import ArmObstacles
from wbc.laws.kinematic_run import integrate
from wbc.laws.lp_law import LPLaw
from wbc.laws.step_context import StepContext
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

GOAL = REACH_GOAL


def arm_row_times(robot: MobileManipulator, repeats: int) -> dict[str, dict[str, float]]:
    """The LP step with and without the rows that keep the arm clear of the table
    (wbc.laws.constraints.arm_obstacles), taking turns BLOCK steps each over the states of the
    guarded reach over the table's edge, and those rows alone (6 rows: 4 points, 2 segments)
    from the step's forward pass, as the law shares it with them. Each step is timed by the
    wall clock and by the process's CPU time (``cpu_*``), which a loaded machine disturbs
    less: the time the process was not running is not counted."""
    task = PoseTask(robot.fkm(TABLE_GOAL))
    obstacles = (TABLE,)
    trajectory = integrate(
        LPLaw(robot, TABLE_PARAMS), TABLE_START, task, DT, 3000, obstacles=obstacles
    ).configurations
    laws = {
        "lp_with_arm_rows": LPLaw(robot, TABLE_PARAMS),
        "lp_without_arm_rows": LPLaw(robot, WITHOUT_ARM_ROWS),
    }
    names = (*laws, "arm_rows")
    wall: dict[str, list[float]] = {name: [] for name in names}
    cpu: dict[str, list[float]] = {name: [] for name in names}

    def timed(name: str, call: Callable[[], object]) -> None:
        start_cpu = time.process_time()  # a system call: outside the wall clock's interval
        start = time.perf_counter()
        call()
        wall[name].append(time.perf_counter() - start)
        cpu[name].append(time.process_time() - start_cpu)

    rows = ArmObstacles(TABLE_PARAMS.arm_obstacle_gain, TABLE_PARAMS.arm_obstacle_margin)
    for block in blocks(trajectory, repeats, laws.values()):
        for name, law in laws.items():
            for q in block:
                timed(name, lambda law=law, q=q: law.step(q, task, DT, obstacles))
        for q in block:
            context = StepContext(
                robot,
                q,
                np.zeros(8),
                np.zeros(8),
                np.zeros(2),
                (),
                None,
                DT,
                obstacles,
                chain=robot.forward(q),
            )
            timed("arm_rows", lambda context=context: rows.rows(context))
    return {
        name: {
            **percentiles(wall[name]),
            **{f"cpu_{key}": value for key, value in percentiles(cpu[name]).items()},
        }
        for name in names
    }


def dqrobotics_times(robot: MobileManipulator, repeats: int) -> dict[str, dict[str, float]]:
    """DQ Robotics' C++ core on the same robot: fkm + pose Jacobian, and a pseudoinverse step."""
    try:
        from dqrobotics import DQ, E_, k_
        from dqrobotics.robot_control import ControlObjective, DQ_PseudoinverseController
        from dqrobotics.robot_modeling import (
            DQ_HolonomicBase,
            DQ_SerialManipulatorDH,
            DQ_WholeBody,
        )
    except ImportError:
        return {}
    base = DQ_HolonomicBase()
    base.set_frame_displacement(1 + E_ * 0.5 * robot.base_height * k_)
    whole_body = DQ_WholeBody(base)
    whole_body.add(DQ_SerialManipulatorDH(np.array(robot.dh)))
    controller = DQ_PseudoinverseController(whole_body)
    controller.set_control_objective(ControlObjective.Pose)
    controller.set_gain(0.6)
    controller.set_damping(0.0)
    goal = DQ(robot.fkm(GOAL))
    q = HOME.copy()
    return {
        "kinematics": percentiles(
            time_calls(lambda: (whole_body.fkm(q), whole_body.pose_jacobian(q)), repeats)
        ),
        "classic": percentiles(
            time_calls(lambda: controller.compute_setpoint_control_signal(q, goal.vec8()), repeats)
        ),
    }


CONVERGENCE_NAMES = {
    ("test 1", "classic"): "holonomic/classic",
    ("test 1", "LP"): "holonomic/lp",
    ("test 2", "classic"): "nonholonomic/cascade",
    ("test 2", "LP"): "nonholonomic/lp",
}
"""The bench's name of each law of each test of section 6.3."""


def convergence_test(robot: MobileManipulator, trials: int) -> dict[str, dict[str, Any]]:
    """Section 6.3 as the dissertation ran it: the laws, goals and timing of
    ``studies.reproduce.efficiency`` (declared there), ``trials`` runs of each law."""
    results = {}
    for test, makers in efficiency.laws(robot).items():
        task = PoseTask(robot.fkm(efficiency.GOALS[test]))
        for label, make_law in makers.items():
            found = efficiency.timed(make_law, task, trials)
            results[CONVERGENCE_NAMES[test, label]] = {
                "iterations": found["iterations"],
                "converged_trials": found["converged"],
                "convergence_time_ms": found["ms"][0],
                "convergence_time_std_ms": found["ms"][1],
                "time_per_iteration_us": found["ms per iteration"] * 1e3,
            }
    return results


def run_bench(
    repeats: int,
    trials: int,
    goals: int,
    robot_file: Path = ROBOT_FILE,
    zoo: Sequence[Path] | None = None,
    zoo_only: bool = False,
    runs: int = 1,
) -> dict:
    """Every figure of `parsimony bench`, measured in this run; progress goes to stderr.

    ``zoo``: the robot descriptions whose step times are taken (None: every one of
    deploy/robots); ``zoo_only``: those step times and nothing else (a quick run); ``runs``:
    how many times the zoo is timed (``zoo_step_times``)."""
    report = {} if zoo_only else robot_figures(repeats, trials, goals, robot_file)
    zoo = deploy_files.zoo() if zoo is None else zoo
    if zoo:
        progress(f"control steps on {len(zoo)} robots" + (f", {runs} runs" if runs > 1 else ""))
        report["zoo"] = zoo_step_times(zoo, repeats, runs)
    return report


def robot_figures(repeats: int, trials: int, goals: int, robot_file: Path) -> dict:
    """The figures of one robot: step times, the LP step's parts, the arm's rows, section 6.3,
    goal shares."""
    robot = MobileManipulator.from_yaml(robot_file)
    progress("control steps")
    steps = step_times(robot, repeats)
    breakdown = lp_breakdown(robot, repeats)
    reference = dqrobotics_times(robot, repeats)
    arm = arm_row_times(robot, repeats)
    report: dict = {
        "step": steps,
        "lp_breakdown_us": breakdown,
        "dqrobotics": reference,
        "arm_rows": arm,
    }
    report["ratios"] = {
        "lp_over_classic": steps["lp"]["median_us"] / steps["classic"]["median_us"],
        "qp_over_classic": steps["qp"]["median_us"] / steps["classic"]["median_us"],
        "lp_with_arm_rows_over_without": (
            arm["lp_with_arm_rows"]["median_us"] / arm["lp_without_arm_rows"]["median_us"]
        ),
        "lp_with_arm_rows_over_without_cpu": (
            arm["lp_with_arm_rows"]["cpu_median_us"] / arm["lp_without_arm_rows"]["cpu_median_us"]
        ),
    }
    if reference:
        report["ratios"]["kinematics_over_dqrobotics"] = (
            steps["kinematics"]["median_us"] / reference["kinematics"]["median_us"]
        )
        report["ratios"]["classic_over_dqrobotics"] = (
            steps["classic"]["median_us"] / reference["classic"]["median_us"]
        )
    progress("section 6.3 convergence test")
    report["convergence"] = convergence_test(robot, trials)
    if goals:
        progress(f"{goals} random goals per family and law")
        report["goals"] = goal_report(robot_file, goals)
    report["goal_pose"] = dq.translation(robot.fkm(GOAL))[1:].tolist()
    return report


def progress(what: str) -> None:
    print(f"bench: {what}", file=sys.stderr, flush=True)


def format_report(report: dict) -> str:
    """The figures as tables, one per section."""
    parts = robot_tables(report) if "step" in report else []
    if "zoo" in report:
        parts += ["", *zoo_tables(report["zoo"])] if parts else zoo_tables(report["zoo"])
    return "\n".join(parts)


def zoo_tables(zoo: dict) -> list[str]:
    """Each robot's step time by law, and the LP step's parts, us."""
    laws = ("lp", "qp", "classic", "cascade")
    steps = [
        {
            "robot (zoo)": name,
            "DOF": row["dof"],
            "base": row["base"],
            **{
                f"{law} {figure}": row["step"][law][f"{figure}_us"] if law in row["step"] else None
                for law in laws
                for figure in ("median", "p99")
            },
            "LP / classic": row["lp_over_classic"],
        }
        for name, row in zoo.items()
    ]
    runs = max(len(row["glue_share"]["runs"]) for row in zoo.values())
    shares = ("median", "low", "high") if runs > 1 else ("median",)
    parts = [
        {
            "LP step, median us by part": name,
            **row["lp_breakdown_us"],
            **{f"glue share {figure}": row["glue_share"][figure] for figure in shares},
        }
        for name, row in zoo.items()
    ]
    over = f", the median of {runs} runs" if runs > 1 else ""
    return [
        f"Control step by robot, us (median, p99; laws in turn on one trajectory{over})",
        table(steps, floatfmt=".1f"),
        "",
        table(parts, floatfmt=".2f"),
    ]


def robot_tables(report: dict) -> list[str]:
    """The tables of ``robot_figures``."""
    steps = [
        {"control step (model + Jacobian + rows + solve)": name, **figures}
        for name, figures in report["step"].items()
    ]
    steps += [
        {"control step (model + Jacobian + rows + solve)": f"DQ Robotics {name}", **figures}
        for name, figures in report["dqrobotics"].items()
    ]
    arm = [
        {"reach over the table (wbc.laws.constraints.arm_obstacles)": name, **figures}
        for name, figures in report["arm_rows"].items()
    ]
    parts = [
        table(steps, floatfmt=".1f"),
        "",
        table(arm, floatfmt=".1f"),
        "",
        "LP step, median us by part",
        table([report["lp_breakdown_us"]], floatfmt=".1f"),
        "",
        table(
            [{"ratios (medians, same run)": n, "ratio": v} for n, v in report["ratios"].items()],
            floatfmt=".2f",
        ),
        "",
        table(
            [{"section 6.3 convergence": n, **row} for n, row in report["convergence"].items()],
            floatfmt=".2f",
        ),
    ]
    for family, result in report.get("goals", {}).items():
        reached = [
            {
                f"{family} goals ({result['goals']})": law,
                **{
                    k: row[k]
                    for k in (
                        "reached",
                        "within_joint_limits",
                        "within_joint_and_speed_limits",
                        "median_time_to_converge_s",
                    )
                },
            }
            for law, row in result["laws"].items()
        ]
        nonzero = [
            {
                "nonzero entries of u": law,
                **{
                    k: row[k]
                    for k in (
                        "median_nonzero_moving",
                        "median_nonzero_settling",
                        "median_nonzero_settling_forward_as_one",
                    )
                },
                "steps by count 0..8 (exact | practical, Upsilon 0.01)": (
                    f"{row['nonzero_histogram']} | {row['practical_histogram']}"
                ),
            }
            for law, row in result["laws"].items()
        ]
        parts += ["", table(reached, floatfmt=".2f"), "", table(nonzero, floatfmt=".1f")]
        for law, row in result["laws"].items():
            if law.startswith("lp"):
                parts.append(
                    f"{law}: every command an optimal LP solution in "
                    f"{row['every_step_optimal']:.2f} of the runs"
                )
            if "plans_per_run" in row:
                parts.append(
                    f"{law}: {row['plans_per_run']:.2f} plans per run, a plan takes "
                    f"{row['plan_median_ms']:.0f} ms median, "
                    f"{row['plan_p99_ms']:.0f} ms p99 "
                    f"({row['plan_cpu_median_ms']:.0f} and "
                    f"{row['plan_cpu_p99_ms']:.0f} ms of its thread's CPU time)"
                )
            if "contacts" in row:
                parts.append(
                    f"{law}: {row['contacts']} runs with a contact, least clearance "
                    f"{row['least_clearance_m']:.3f} m"
                )
            if law.startswith("lp") and row.get("failures"):
                parts.append(f"{law}: not reached, by reason:")
                parts += [f"  {n} x {reason}" for reason, n in row["failures"].items()]
    return parts
