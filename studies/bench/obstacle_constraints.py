"""The obstacle constraints compared on the same set-ups: 5.28, the vector-field inequality, 5.19.

Run as ``python -m studies.bench.obstacle_constraints [--seeds N] [--kinematic-seeds M]
[--workers W] [--json]``. Each variant (``VARIANTS``) is the obstacle experiment's law (6.2.3,
``studies.gain_sets.LP_PARAMS``) with the gains it names. Each runs the obstacle
experiment's set-up of seeds 0..M-1 kinematically (q += u dt at 50 Hz from the seed's start, to
the goal above its bin, ``wbc.laws.kinematic_run``), and of seeds 0..N-1 and ``HELD_OUT`` on the
whole simulated loop (``parsimony experiment obstacle`` in lockstep, the controller told the
variant's gains), W runs at a time. For each it prints the share that converged (``||e||`` under
``analysis.judge.CONVERGED_ERROR`` within ``TIME_LIMIT_S`` of simulated time), the runs with a
contact (the simulator's count; kinematically, a step with the base's disc over an obstacle's),
the least clearance between the base's disc and the obstacle over every run, the median nonzero
entries of u while moving (``||e|| > MOVING_ERROR``, every such step of every run pooled, as
``parsimony bench`` counts them), the time to converge (median and p99 over the runs that
converged), and the seeds that did not converge with their final error. Nothing is asserted.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Mapping, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from analysis.judge import CONVERGED_ERROR, JUDGED, converged_at, messages, origin_s, the_run
from messages.topics import CONTROL_DIAGNOSTICS, SUPERVISOR_STATUS
from outputs.stdout import emit, json_text, result_only_stdout, table
from profiles.profile import load_profile
from record.sessions import load_session
from sim2d.scenarios import scenario
from studies.bench.sim_experiments import experiment_or_none
from studies.experiment import PROFILES, TIME_LIMIT_S, Options
from studies.gain_sets import LP_PARAMS
from studies.goal_sets import MOVING_ERROR
from wbc.geometry.scenarios import DT
from wbc.laws.kinematic_run import integrate
from wbc.laws.lp_law import LPLaw
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

VARIANTS: Mapping[str, Mapping[str, Any]] = {
    "5.28, 5.10 (the dissertation's)": {
        "obstacle_mode": "border",
        "obstacle_circulation": 0.0,
        "error_bound": "derivative",
    },
    "5.28 + circulation, 5.7": {"obstacle_mode": "border"},
    "VFI + circulation, 5.7": {"obstacle_mode": "vector_field"},
    "VFI, 5.7": {"obstacle_mode": "vector_field", "obstacle_circulation": 0.0},
    "VFI, 5.10": {
        "obstacle_mode": "vector_field",
        "obstacle_circulation": 0.0,
        "error_bound": "derivative",
    },
    "5.19, 5.7": {"obstacle_mode": "conservative"},
}
"""Each law compared: the obstacle experiment's gains with these in their place. 5.28 with the
rate bound 5.10 and no circulation term is the dissertation's; 5.7 bounds ||u||_1 by the error
instead (the experiment's), the circulation term (wbc.laws.objectives.obstacle_circulation) takes a
base that stalled by an obstacle round it; the VFI is wbc.laws.constraints.obstacle_vector_field."""
HELD_OUT = (772,)
"""A seed apart from 0..N-1: start, obstacle and bin near one line (5.28 stalled at 0.56)."""


@dataclass(frozen=True)
class Outcome:
    """One run of one variant on one seed."""

    variant: str
    loop: str
    seed: int
    converged: bool
    contact: bool
    clearance_m: float
    """The least distance between the base's disc and an obstacle's, m."""
    final_error: float
    seconds: float
    """Simulated time to ||e|| < CONVERGED_ERROR for good (the time limit when not)."""
    moving_nonzero: tuple[int, ...]
    """Nonzero entries of u at each step with ||e|| > MOVING_ERROR."""


def kinematic_run(variant: str, seed: int) -> Outcome:
    """The variant's law from the seed's start to the goal above its bin, q += u dt."""
    profile = load_profile(PROFILES["lp"])
    robot = MobileManipulator.from_yaml(profile.robot)
    setup = scenario("obstacle", robot, seed)
    goal = setup.goal(profile.scene.goal.height_m, profile.scene.goal.offset)
    law = LPLaw(robot, replace(LP_PARAMS["obstacle"], **VARIANTS[variant]))
    run = integrate(
        law,
        np.array(setup.start),
        PoseTask(goal),
        DT,
        round(TIME_LIMIT_S / DT),
        CONVERGED_ERROR,
        setup.obstacles,
    )
    base = np.array(run.configurations)[:, :2]
    clearance = min(
        float(np.min(np.hypot(base[:, 0] - c.x, base[:, 1] - c.y)))
        - c.radius
        - robot.base.body_radius
        for c in setup.obstacles
    )
    moving = tuple(out.nonzero for out in run.outputs if out.error_norm > MOVING_ERROR)
    return Outcome(
        variant,
        "kinematic",
        seed,
        run.converged,
        clearance < 0.0,
        clearance,
        run.final_error,
        len(run.outputs) * DT,
        moving,
    )


def sim_run(variant: str, seed: int, directory: Path) -> Outcome | None:
    """``parsimony experiment obstacle --seed SEED`` in lockstep with the variant's gains,
    judged from its recording (deleted after); None when it could not run (said, with why)."""
    out = directory / f"{list(VARIANTS).index(variant)}-{seed}"
    options = Options(name="obstacle", seed=seed, out=out, gains=VARIANTS[variant])
    report = experiment_or_none(options, f"{variant} seed {seed}")
    if report is None:
        return None
    run, _ = the_run(load_session(out / "session.mcap", JUDGED), TIME_LIMIT_S)
    shutil.rmtree(out, ignore_errors=True)
    diagnostics = [d for d in messages(run, CONTROL_DIAGNOSTICS) if d.status == "optimal"]
    since = converged_at(messages(run, CONTROL_DIAGNOSTICS), messages(run, SUPERVISOR_STATUS))
    seconds = TIME_LIMIT_S if since is None else since - origin_s(run)
    moving = tuple(
        d.nonzero for d in diagnostics if d.error_norm is not None and d.error_norm > MOVING_ERROR
    )
    return Outcome(
        variant,
        "sim",
        seed,
        report["converged"],
        report["contacts"] > 0,
        report["min_obstacle_clearance_m"],
        report["final_error"],
        seconds,
        moving,
    )


def said(future: Future) -> Outcome | None:
    """A run's outcome, logged to stderr as it lands."""
    found = future.result()
    if found is not None:
        print(
            f"[bench] {found.loop} {found.variant} seed {found.seed}: converged="
            f"{found.converged} {found.seconds:.1f} s error {found.final_error:.3g} "
            f"clearance {found.clearance_m:.3f}",
            file=sys.stderr,
            flush=True,
        )
    return found


def summary(
    loop: str, variant: str, found: Sequence[Outcome | None], held_out: Sequence[int] = ()
) -> dict[str, Any]:
    """A variant's runs on one loop: the seeds of 0..N-1 summarised, ``held_out`` apart."""
    runs = [o for o in found if o is not None and o.seed not in held_out]
    times = [o.seconds for o in runs if o.converged]
    moving = [m for o in runs for m in o.moving_nonzero]
    row = {
        "loop": loop,
        "constraint": variant,
        "runs": len(runs),
        "did_not_run": sum(o is None for o in found),
        "converged": round(sum(o.converged for o in runs) / max(len(runs), 1), 3),
        "with_contact": sum(o.contact for o in runs),
        "least_clearance_m": round(min((o.clearance_m for o in runs), default=math.nan), 3),
        "nonzero_moving": float(np.median(moving)) if moving else math.nan,
        "converge_s_median": round(float(np.median(times)), 1) if times else math.nan,
        "converge_s_p99": round(float(np.percentile(times, 99)), 1) if times else math.nan,
        "not_converged": [f"{o.seed}({o.final_error:.2f})" for o in runs if not o.converged],
    }
    for seed in held_out:
        run = next((o for o in found if o is not None and o.seed == seed), None)
        row[f"seed_{seed}"] = (
            "-"
            if run is None
            else f"{run.seconds:.1f} s"
            if run.converged
            else f"no ({run.final_error:.2f})"
        )
    return row


def brief(seeds: list[str], shown: int = 5) -> str:
    """The first ``shown`` seeds that did not converge, and how many more."""
    more = f" +{len(seeds) - shown} more" if len(seeds) > shown else ""
    return " ".join(seeds[:shown]) + more


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--seeds",
        type=int,
        default=40,
        help="seeds 0..N-1 of the simulated loop, besides the held-out one",
    )
    parser.add_argument(
        "--kinematic-seeds", type=int, default=200, help="seeds 0..M-1 of the kinematic loop"
    )
    parser.add_argument(
        "--workers",
        type=int,
        default=min(2, os.cpu_count() or 1),
        help="runs at once (default: two, or one on one core)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    args = parser.parse_args(argv)
    sim_seeds = [*range(args.seeds), *HELD_OUT] if args.seeds > 0 else []
    started = time.monotonic()
    with tempfile.TemporaryDirectory() as directory, ProcessPoolExecutor(args.workers) as pool:
        simulated = {
            v: [pool.submit(sim_run, v, s, Path(directory)) for s in sim_seeds] for v in VARIANTS
        }
        kinematic = {
            v: [pool.submit(kinematic_run, v, s) for s in range(args.kinematic_seeds)]
            for v in VARIANTS
        }
        rows = [
            summary("sim", v, [said(f) for f in found], HELD_OUT)
            for v, found in simulated.items()
            if found
        ]
        rows += [
            summary("kinematic", v, [said(f) for f in found])
            for v, found in kinematic.items()
            if found
        ]
    study = {
        "sim_seeds": len(sim_seeds),
        "kinematic_seeds": args.kinematic_seeds,
        "workers": args.workers,
        "minutes": round((time.monotonic() - started) / 60.0, 1),
    }
    if args.json:
        emit(json_text({"bench": "obstacle_constraints", "study": study, "variants": rows}))
    else:
        emit(table([{**row, "not_converged": brief(row["not_converged"])} for row in rows]))
        emit(" ".join(f"{k}={v}" for k, v in study.items()))
    return 0


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
