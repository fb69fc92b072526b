"""`parsimony bench`: what one control step costs, and the convergence test of section 6.3.

Step times are taken on a replay of a closed-loop trajectory, so the LP's warm start sees the
small changes it sees in a control loop. Every figure comes from one run on this machine.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from parsimony.kinematic_demo import DT, ROBOT_FILE, START
from wbc import dq
from wbc.cascade_law import CascadeLaw, CascadeParams
from wbc.kinematic_run import integrate
from wbc.lp_law import LPLaw, LPParams
from wbc.pinv_law import PinvParams, PseudoinverseLaw
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

GOAL = np.array([0.58, 0.05, -0.16, 0.3, 0.15, -0.66, -0.03, -0.36])
CONVERGENCE_GOAL = np.array([0.45, -0.29, -0.12, 0.23, -0.26, 0.14, -0.28, -0.3])
ARM_GOAL_LOW = np.array([-0.5, -0.8, -0.8, -0.5, -0.8])
ARM_GOAL_HIGH = np.array([0.5, 0.3, 0.3, 0.5, 0.8])


def percentiles(samples_s: list[float]) -> dict[str, float]:
    """Median and p99 of durations in seconds, in microseconds."""
    values = np.asarray(samples_s) * 1e6
    return {"median_us": float(np.median(values)), "p99_us": float(np.percentile(values, 99))}


def time_calls(call: Callable[[], object], repeats: int) -> list[float]:
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        samples.append(time.perf_counter() - start)
    return samples


def step_times(robot: MobileManipulator, repeats: int) -> dict[str, dict[str, float]]:
    """Whole control steps (model, Jacobian, rows, solve) along a recorded LP trajectory."""
    task = PoseTask(robot.fkm(GOAL))
    trajectory = integrate(LPLaw(robot), START, task, DT, 3000).configurations
    results: dict[str, dict[str, float]] = {}
    laws = {"lp": LPLaw(robot), "classic": PseudoinverseLaw(robot), "cascade": CascadeLaw(robot)}
    for name, law in laws.items():
        samples: list[float] = []
        while len(samples) < repeats:
            law.reset()
            for q in trajectory[: repeats - len(samples)]:
                start = time.perf_counter()
                law.step(q, task, DT)
                samples.append(time.perf_counter() - start)
        results[name] = percentiles(samples)
    results["kinematics"] = percentiles(time_calls(lambda: robot.kinematics(GOAL), repeats))
    return results


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
    q = START.copy()
    return {
        "kinematics": percentiles(
            time_calls(lambda: (whole_body.fkm(q), whole_body.pose_jacobian(q)), repeats)
        ),
        "classic": percentiles(
            time_calls(lambda: controller.compute_setpoint_control_signal(q, goal.vec8()), repeats)
        ),
    }


def convergence_test(robot: MobileManipulator, trials: int) -> dict[str, dict[str, float]]:
    """Section 6.3: the same pose task repeated; iterations to ||e|| < 1e-3, time per iteration.

    Test 1 (holonomic): classic law and LP without extra constraints; test 2 (nonholonomic):
    the cascade and the LP with 5.12 and joint limits (k = 1, b_l = 0.99). eta = 5, beta = 40.
    """
    task = PoseTask(robot.fkm(CONVERGENCE_GOAL))
    tests = {
        "holonomic/classic": lambda: PseudoinverseLaw(robot, PinvParams(eta=5.0)),
        "holonomic/lp": lambda: LPLaw(
            robot, LPParams(eta=5.0, beta=40.0, nonholonomic=False, safety_factor=1.0,
                            joint_gain=1e3, obstacle_mode="off")),  # fmt: skip
        "nonholonomic/cascade": lambda: CascadeLaw(robot, CascadeParams(eta=5.0)),
        "nonholonomic/lp": lambda: LPLaw(
            robot, LPParams(eta=5.0, beta=40.0, safety_factor=0.99, obstacle_mode="off")),
    }  # fmt: skip
    results = {}
    for name, make_law in tests.items():
        iterations, durations = [], []
        for _ in range(trials):
            law = make_law()
            start = time.perf_counter()
            run = integrate(law, START, task, DT, 2000)
            durations.append(time.perf_counter() - start)
            iterations.append(len(run.outputs) if run.converged else -1)
        per_iteration = np.array(durations) / np.abs(iterations)
        results[name] = {
            "iterations": int(np.median(iterations)),
            "converged_trials": int(np.sum(np.array(iterations) > 0)),
            "convergence_time_ms": float(np.mean(durations) * 1e3),
            "convergence_time_std_ms": float(np.std(durations) * 1e3),
            "time_per_iteration_us": float(np.median(per_iteration) * 1e6),
        }
    return results


def random_goal_success(robot: MobileManipulator, goals: int, seed: int = 1) -> dict[str, float]:
    """Share of random pose goals (base 0.3-1 m ahead, arm inside its limits) reached in 60 s."""
    rng = np.random.default_rng(seed)
    laws = {
        "lp (5.29 exactly, w = 0)": lambda: LPLaw(robot, LPParams(velocity_cost=0.0)),
        "lp (default, w = 1e-3)": lambda: LPLaw(robot),
        "cascade": lambda: CascadeLaw(robot),
    }
    reached = dict.fromkeys(laws, 0)
    for _ in range(goals):
        arm_start = np.clip(START[3:] + rng.uniform(-0.3, 0.3, 5), ARM_GOAL_LOW, ARM_GOAL_HIGH)
        start = np.concatenate((np.zeros(3), arm_start))
        base_goal = [rng.uniform(0.3, 1.0), rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4)]
        goal = np.concatenate((base_goal, rng.uniform(ARM_GOAL_LOW, ARM_GOAL_HIGH)))
        task = PoseTask(robot.fkm(goal))
        for name, make_law in laws.items():
            reached[name] += integrate(make_law(), start, task, DT, 3000).converged
    return {name: count / goals for name, count in reached.items()}


def run_bench(repeats: int, trials: int, goals: int, robot_file: Path = ROBOT_FILE) -> dict:
    robot = MobileManipulator.from_yaml(robot_file)
    steps = step_times(robot, repeats)
    reference = dqrobotics_times(robot, repeats)
    report: dict = {"step": steps, "dqrobotics": reference}
    report["ratios"] = {
        "lp_over_classic": steps["lp"]["median_us"] / steps["classic"]["median_us"]
    }
    if reference:
        report["ratios"]["kinematics_over_dqrobotics"] = (
            steps["kinematics"]["median_us"] / reference["kinematics"]["median_us"]
        )
        report["ratios"]["classic_over_dqrobotics"] = (
            steps["classic"]["median_us"] / reference["classic"]["median_us"]
        )
    report["convergence"] = convergence_test(robot, trials)
    if goals:
        report["random_goal_success"] = random_goal_success(robot, goals)
    report["goal_pose"] = dq.translation(robot.fkm(GOAL))[1:].tolist()
    return report


def format_report(report: dict) -> str:
    lines = ["control step (model + Jacobian + rows + solve)   median us    p99 us"]
    for name, figures in report["step"].items():
        lines.append(f"  {name:<44} {figures['median_us']:9.1f} {figures['p99_us']:9.1f}")
    for name, figures in report["dqrobotics"].items():
        label = f"DQ Robotics {name}"
        lines.append(f"  {label:<44} {figures['median_us']:9.1f} {figures['p99_us']:9.1f}")
    lines.append("ratios (medians, same run)")
    lines += [f"  {name:<44} {value:9.2f}" for name, value in report["ratios"].items()]
    lines.append("section 6.3 convergence   iterations  converged  time ms (std)   us/iteration")
    for name, row in report["convergence"].items():
        lines.append(
            f"  {name:<22} {row['iterations']:>10} {row['converged_trials']:>10}"
            f"  {row['convergence_time_ms']:7.2f} ({row['convergence_time_std_ms']:.2f})"
            f"  {row['time_per_iteration_us']:10.1f}"
        )
    if "random_goal_success" in report:
        lines.append("random pose goals reached (share)")
        lines += [
            f"  {name:<44} {share:9.2f}" for name, share in report["random_goal_success"].items()
        ]
    return "\n".join(lines)
