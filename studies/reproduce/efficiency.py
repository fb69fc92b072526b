"""Section 6.3 as the dissertation ran it: the same pose task repeated, timed, for the classic
law and the LP; test 1 holonomic (no constraint on the LP but 5.10), test 2 nonholonomic (the
cascade; the LP with 5.12 and the joint limits of k 1, b_l 0.99), each to its own goal."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from studies.gain_sets import bare_5_29
from studies.reproduce import laws as L
from studies.reproduce.dissertation import SECTION_6_3
from studies.reproduce.table import Row
from wbc.geometry.scenarios import CONVERGENCE_GOAL, DT, HOME, REACH_GOAL
from wbc.laws.cascade_law import CascadeLaw, CascadeParams
from wbc.laws.constraints.error_bound import ErrorBound
from wbc.laws.kinematic_run import integrate
from wbc.laws.law_output import Law
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.pinv_law import PinvParams, PseudoinverseLaw
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

ETA, BETA = 5.0, 40.0
"""The gains of both tests: eta 5 for both laws, beta 40 for the LP."""
GOALS = {"test 1": CONVERGENCE_GOAL, "test 2": REACH_GOAL}
"""The goal configuration of each test ("the desired pose was different with respect to the
first test"): test 2 takes the pose experiment's."""
TRIALS = 500
"""Trials of each law in each test by default: the dissertation ran 10,000; 500 take about
half a minute (``--trials``)."""
STEPS = 2000


def laws(robot: MobileManipulator) -> dict[str, dict[str, Callable[[], Law]]]:
    """Each test's laws, as makers of a fresh law for each trial. None has a speed bound: 6.3
    states none (``laws.UNBOUNDED_SPEED``)."""
    free = robot.with_velocity_max(np.full(robot.dof, L.UNBOUNDED_SPEED))
    holonomic = LPParams(eta=ETA, beta=BETA, nonholonomic=False)
    nonholonomic = bare_5_29(LPParams(eta=ETA, beta=BETA, joint_gain=1.0, safety_factor=0.99))
    return {
        "test 1": {
            "classic": lambda: PseudoinverseLaw(free, PinvParams(eta=ETA)),
            "LP": lambda: LPLaw(free, holonomic, constraints=[ErrorBound(BETA)], objectives=[]),
        },
        "test 2": {
            "classic": lambda: CascadeLaw(free, CascadeParams(eta=ETA)),
            "LP": lambda: LPLaw(free, nonholonomic),
        },
    }


def timed(make_law: Callable[[], Law], task: PoseTask, trials: int) -> dict:
    """``trials`` runs of a fresh law to ||e|| < 1e-3, after one untimed: iterations (or
    their range over the trials, -1 for a trial that did not converge), trials converged,
    convergence time mean and standard deviation (ms) and per iteration (ms)."""
    integrate(make_law(), HOME, task, DT, STEPS)
    iterations, durations = [], []
    for _ in range(trials):
        law = make_law()
        start = time.perf_counter()
        run = integrate(law, HOME, task, DT, STEPS)
        durations.append((time.perf_counter() - start) * 1e3)
        iterations.append(len(run.outputs) if run.converged else -1)
    mean = float(np.mean(durations))
    low, high = min(iterations), max(iterations)
    return {
        "iterations": low if low == high else [low, high],
        "converged": int(np.sum(np.array(iterations) > 0)),
        "ms": [mean, float(np.std(durations))],
        "ms per iteration": mean / max(iterations),
    }


def section_6_3(robot: MobileManipulator, trials: int) -> tuple[list[Row], list[dict]]:
    """The rows of both tests and what each law ran."""
    rows, ran = [], []
    for test, makers in laws(robot).items():
        task = PoseTask(robot.fkm(GOALS[test]))
        found = {label: timed(make, task, trials) for label, make in makers.items()}
        theirs = SECTION_6_3[test]
        kind = "holonomic" if test == "test 1" else "nonholonomic"
        goal = ", ".join(f"{v:g}" for v in GOALS[test])
        rows += [
            Row(
                f"6.3.{test}.iterations",
                "6.3",
                f"{test} ({kind}; goal: the pose of q = [{goal}]): iterations to ||e|| < 1e-3 "
                "(classic, LP), each over its trials",
                theirs["iterations"],
                [found["classic"]["iterations"], found["LP"]["iterations"]],
                "the same for both",
                f"6.3 {test}",
                ("classic", "LP"),
            ),
            Row(
                f"6.3.{test}.time",
                "6.3",
                f"{test}: trials, trials converged (classic, LP); "
                "convergence time of a trial, mean and std, ms (classic, LP); ms per iteration",
                {
                    "trials": theirs["trials"],
                    "classic": list(theirs["classic_ms"]),
                    "LP": list(theirs["lp_ms"]),
                    "per iteration": [
                        round(theirs[k][0] / theirs["iterations"], 2)
                        for k in ("classic_ms", "lp_ms")
                    ],
                },
                {
                    "trials": trials,
                    "converged": [found[k]["converged"] for k in found],
                    "classic": found["classic"]["ms"],
                    "LP": found["LP"]["ms"],
                    "per iteration": [found[k]["ms per iteration"] for k in found],
                },
                "classic faster",
                f"6.3 {test}",
                ("classic", "LP"),
                timed=True,
            ),
        ]
        ran += [
            {"experiment": f"6.3 {test}", "label": label, "ran": L.describe(make())}
            for label, make in makers.items()
        ]
    return rows, ran
