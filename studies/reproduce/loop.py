"""`parsimony reproduce --loop`: the set-ups of section 6.2 on the whole simulated loop.

Each law of the rows runs through ``studies.experiment`` in lockstep (simulator, camera,
vision tracker, state estimator and controller, each a process; the goal and the state seen by
the camera), with the gains of its kinematic run (``runs.laws_of``, passed as the experiment's
``--gain``: one declaration). Each recording is read back (``recorded``) and given to the
same row functions as the kinematic runs (``rows``); each row is labelled as on the loop and
printed beside its kinematic one (``beside``). A run of the loop ends by the loop's rule
(``analysis.run_end``): ``HOLD_S`` after its error stayed under ``CONVERGED_ERROR``, else at the
time limit.
"""

from __future__ import annotations

import dataclasses
import re
import sys
import time
from pathlib import Path
from typing import Any

from analysis.run_end import CONVERGED_ERROR, HOLD_S
from studies.experiment import PROFILES, SESSION_FILE, Options, run_experiment
from studies.gain_sets import LP_PARAMS
from studies.reproduce import laws as L
from studies.reproduce import rows as R
from studies.reproduce.recorded import recorded
from studies.reproduce.runs import NAMES, Experiment, laws_of
from studies.reproduce.table import Row
from wbc.geometry.scenarios import OBSTACLE
from wbc.laws.cascade_law import CascadeLaw, CascadeParams
from wbc.laws.law_output import Law
from wbc.laws.lp_law import LPLaw
from wbc.robot import MobileManipulator

PLACE = "on the loop"
"""How a row of the loop is labelled."""
LOOP_LAWS = {"pose": R.MAIN, "position": R.MAIN, "obstacle": (L.LP, L.LP_BORDER, L.LP_5_29)}
"""The set-ups of 6.2 and the laws each runs on the loop: those of its rows in 6.2 that a
controller process runs (not the pseudoinverse nor a law without the robot's bounds)."""
LABELS = tuple(dict.fromkeys(label for labels in LOOP_LAWS.values() for label in labels))
FRAMES = (
    "u, headings and the residual in F0, the reference marker's frame, which the "
    "controller steps in (yaw 0.3 rad in the simulator's world); paths and clearance "
    "from the simulator's truth in its world, the kinematic runs' frame"
)


def controller_of(law: Law, name: str) -> tuple[str, dict[str, Any]]:
    """The controller process that runs ``law`` in set-up ``name``, and the gains to give it:
    those of its parameters that differ from what the experiment gives that controller."""
    if isinstance(law, CascadeLaw):
        return "cascade", changed(law.params, CascadeParams())
    if isinstance(law, LPLaw):
        return "lp", changed(law.params, LP_PARAMS[name])
    raise ValueError(f"no controller process runs {type(law).__name__}")


def changed(params: Any, base: Any) -> dict[str, Any]:
    return {
        f.name: getattr(params, f.name)
        for f in dataclasses.fields(params)
        if getattr(params, f.name) != getattr(base, f.name)
    }


def folder(label: str) -> str:
    """A label as a directory name: "cascade, saturated" -> "cascade_saturated"."""
    return re.sub(r"[^A-Za-z0-9.]+", "_", label).strip("_")


def run_loop(
    robot: MobileManipulator,
    names: tuple[str, ...],
    labels: tuple[str, ...],
    out: Path,
    time_limit_s: float,
    figures: bool = True,
) -> tuple[dict[str, Experiment], list[dict]]:
    """Each law of ``labels`` in each set-up of ``names`` on the loop, its run in
    ``out/NAME/LABEL`` (recording, report, and its figures if ``figures``): the experiments
    as the rows take them, and what each run was (its controller, gains, verdict and wall
    time)."""
    chosen = [
        (name, label)
        for name in NAMES
        if name in names and name in LOOP_LAWS
        for label in LOOP_LAWS[name]
        if label in labels
    ]
    runs: dict[str, dict[str, Any]] = {}
    done: list[dict] = []
    for count, (name, label) in enumerate(chosen, 1):
        law = laws_of(robot, name)[label]
        controller, gains = controller_of(law, name)
        where = out / name / folder(label)
        print(
            f"[reproduce] the loop, {count}/{len(chosen)}: {name}, {label}",
            file=sys.stderr,
            flush=True,
        )
        report = run_experiment(
            Options(
                name, controller, where, time_limit_s=time_limit_s, gains=gains, figures=figures
            )
        )
        obstacles = (OBSTACLE,) if name == "obstacle" else ()
        ran = (
            f"the whole loop in lockstep ({PROFILES[controller].name}: camera, vision "
            "tracker, estimator, controller), its base command scaled into the wheel speed "
            f"limit as every controller sends it; {L.describe(law, obstacles)}"
        )
        runs.setdefault(name, {})[label] = (
            recorded(where / SESSION_FILE, time_limit_s),
            law.params.eta,
            ran,
        )
        done.append(
            {
                "experiment": name,
                "label": label,
                "controller": controller,
                "gains": gains,
                "out": str(where),
                "report": report,
            }
        )
    until = (
        f"||e|| < {CONVERGED_ERROR:g} held {HOLD_S:g} s (the loop's rule), else {time_limit_s:g} s"
    )
    found = {}
    for name, made in runs.items():
        first, eta, _ = next(iter(made.values()))
        found[name] = Experiment(
            name,
            first.goal,
            eta,
            {label: r.run for label, (r, _, _) in made.items()},
            {label: ran for label, (_, _, ran) in made.items()},
            (OBSTACLE,) if name == "obstacle" else (),
            {label: r.tasks for label, (r, _, _) in made.items()},
            {label: r.truth for label, (r, _, _) in made.items()},
            until,
        )
    return found, done


def loop_rows(
    robot: MobileManipulator, found: dict[str, Experiment], done: list[dict]
) -> list[Row]:
    """The rows of 6.2, table 6.1 and 6.3's step time of the runs ``found``, each labelled as
    on the loop, and the controller's whole step from its counters."""
    rows = [
        row
        for name in ("pose", "position")
        if name in found
        for row in R.task_rows(robot, found[name])
    ]
    rows += [
        row for name in ("pose", "position") if name in found for row in R.effort_rows(found[name])
    ]
    if "obstacle" in found:
        rows += R.obstacle_rows(robot, found["obstacle"])
    rows += R.step_time_rows(found)
    rows = [on_loop(row) for row in rows]
    return rows + handler_rows(done)


def on_loop(row: Row) -> Row:
    """``row`` labelled as on the loop: its key, its result and its experiments."""
    return dataclasses.replace(
        row,
        key=f"loop.{row.key}",
        result=f"{PLACE}: {row.result}",
        experiment=", ".join(f"{name} {PLACE}" for name in row.experiment.split(", ")),
    )


HANDLER = "handler.robot/state_us"
"""The controller's counters of its handling of a state (``components.durations``)."""


def handler_rows(done: list[dict]) -> list[Row]:
    """Section 6.3's 20 ms against the controller's whole step on the loop: its handling of a
    state (the law, the messages in and out), median and p99 over each run, ms."""
    out = []
    for label in dict.fromkeys(run["label"] for run in done):
        runs = [run for run in done if run["label"] == label]
        found = {}
        for run in runs:
            counters = run["report"]["durations_us"].get("controller", {})
            found[run["experiment"]] = [
                counters.get(f"{HANDLER}_median", 0) / 1e3,
                counters.get(f"{HANDLER}_p99", 0) / 1e3,
            ]
        names = ", ".join(f"{run['experiment']} {PLACE}" for run in runs)
        out.append(
            Row(
                f"loop.step_time.{label}.handler",
                "6.3",
                f"{PLACE}: {label}: the "
                "controller's whole step (its handling of a state: the law and the "
                "messages), median and p99 of each run, ms",
                f"under {R.PERIOD_MS:g} ms",
                found,
                f"p99 < {R.PERIOD_MS:g}",
                names,
                (label,),
                timed=True,
            )
        )
    return out


def beside(rows: list[Row], loop: list[Row]) -> list[Row]:
    """``rows`` with each row of ``loop`` after the row it repeats on the loop (a row of the
    loop alone after the one whose key begins its own), the rest at the end."""
    left = list(loop)
    out = []
    for row in rows:
        out.append(row)
        mine = [r for r in left if r.key == f"loop.{row.key}"]
        mine += [r for r in left if r.key.startswith(f"loop.{row.key}.")]
        out += mine
        left = [r for r in left if r not in mine]
    return out + left


def summary(done: list[dict], wall_s: float) -> dict:
    """What the loop ran and how long it took."""
    return {
        "wall_s": round(wall_s, 1),
        "sim_s": round(sum(run["report"]["sim_time_s"] for run in done), 2),
        "runs": [
            {k: run[k] for k in ("experiment", "label", "controller", "gains", "out")}
            | {
                k: run["report"][k]
                for k in (
                    "converged",
                    "sim_time_s",
                    "wall_time_s",
                    "real_time_factor",
                    "lockstep_timeouts",
                )
            }
            for run in done
        ],
    }


def summary_line(ran: dict) -> str:
    """The loop's run time (``summary``), as the command prints it."""
    return (
        f"The whole loop (lockstep): {len(ran['runs'])} runs, {ran['sim_s']:g} s "
        f"simulated in {ran['wall_s']:g} s of wall time; {FRAMES}."
    )


def loop(
    robot: MobileManipulator,
    names: tuple[str, ...],
    labels: tuple[str, ...],
    out: Path,
    time_limit_s: float,
    figures: bool = True,
) -> tuple[list[Row], list[dict[str, str]], dict]:
    """The rows of the loop, what each law ran there, and the summary (``summary``); each run
    draws its figures if ``figures``."""
    started = time.monotonic()
    found, done = run_loop(robot, names, labels, out, time_limit_s, figures)
    laws = [
        {"experiment": f"{name} {PLACE}", "label": label, "ran": text}
        for name, experiment in found.items()
        for label, text in experiment.laws.items()
    ]
    return loop_rows(robot, found, done), laws, summary(done, time.monotonic() - started)
