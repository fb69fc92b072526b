"""The LP with and without its input change term (future work 1 of 7.2), on the same goals.

Run as ``python -m studies.bench.input_change [--goals N] [--workers W] [--variants A,B] [--json]``.
Each variant of the LP law (``VARIANTS``: the default law, the same law with the input change
term of deploy/sim_smooth.yaml, and the term's ``change`` form at two weights) is run on the
'ahead' goals of ``parsimony bench`` (``studies.goal_sets``: the same seed, the same runs of
60 s at 50 Hz), for the pose task and the position task of each goal. Printed per variant and
task: the share of goals reached inside every limit, the median nonzero entries of u while
moving (||e|| > 0.05) and over the last 2 s, and on the goals both the variant and the default
LP reached, the medians of table 6.1's metrics 1 to 4 from the first command (as table 6.1
takes them) and of 3 and 4 from rest (u = 0 before the first command, so the jump from rest
counts), each beside the median of its ratio to the default LP's, goal by goal.
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

import numpy as np

from outputs.stdout import emit, json_text, result_only_stdout, table
from profiles.deploy_files import ROBOT_FILE
from studies.gain_sets import input_change_gains
from studies.goal_families import GOAL_SEED
from studies.goal_sets import Attempt, parsimony, shares
from studies.study.attempts import sweep_attempts
from studies.study.schema import Study
from wbc.robot import MobileManipulator

VARIANTS: dict[str, dict[str, Any]] = {
    "lp": {},
    "lp with input change": input_change_gains(),
    "lp change w=0.01": {"input_change": 0.01, "input_change_form": "change"},
    "lp change w=0.05": {"input_change": 0.05, "input_change_form": "change"},
}
"""The laws compared, LPParams() with these gains changed (names without commas): the default
LP (the term off), the term as deploy/sim_smooth.yaml declares it, and the term's ``change``
form, w ||u - u_prev||_1, at two weights."""
TASKS = ("pose", "position")


def measure(names: list[str], count: int, workers: int) -> dict[str, dict[str, list[Attempt]]]:
    """Every variant's attempts at the 'ahead' goals, per task (a study on the local pool)."""
    laws = [{"law": "lp", "label": name, "gains": VARIANTS[name]} for name in names]
    found: dict[str, dict[str, list[Attempt]]] = {}
    for task in TASKS:
        study = Study.model_validate(
            {"name": f"input-change-{task}", "families": ["ahead"], "task": task}
            | {"goals": count, "seeds": [GOAL_SEED], "laws": laws}
        )
        ran = sweep_attempts(study, workers)
        found[task] = {name: ran[("ahead", task, GOAL_SEED, name)] for name in names}
    return found


REFERENCE = "lp"
"""The variant every other is compared with, goal by goal."""
FIELDS = {
    "metric 1": ("velocity_l1", False),
    "metric 2": ("velocity_l2", False),
    "metric 3": ("acceleration_l1", False),
    "metric 4": ("acceleration_l2", False),
    "metric 3 from rest": ("acceleration_l1", True),
    "metric 4 from rest": ("acceleration_l2", True),
}
"""The figures of each run compared: a ``ControlEffort`` field, from rest or not."""


def summary(found: dict[str, dict[str, list[Attempt]]], dof: int) -> list[dict[str, Any]]:
    """One row per task and variant: its share reached, its nonzero entries, and on the goals
    both it and ``REFERENCE`` reached inside every limit, each metric's median and the median
    of its ratio to the reference's, goal by goal."""
    rows = []
    for task, variants in found.items():
        reference = variants.get(REFERENCE)
        for name, attempts in variants.items():
            counts = parsimony(attempts, dof)
            pairs = [
                (a, b)
                for a, b in zip(attempts, reference or attempts, strict=True)
                if a.within_all_limits and b.within_all_limits
            ]
            row = {
                "task": task,
                "law": name,
                "reached inside every limit": shares(attempts)["within_joint_and_speed_limits"],
                "nonzero moving": counts["median_nonzero_moving"],
                "nonzero last 2 s": counts["median_nonzero_settling"],
                "goals compared": len(pairs),
            }
            for label, (field, from_rest) in FIELDS.items():
                mine = [_metric(a, field, from_rest) for a, _ in pairs]
                theirs = [_metric(b, field, from_rest) for _, b in pairs]
                row[label] = _median(mine)
                row[f"{label} / {REFERENCE}"] = _median(list(np.divide(mine, theirs)))
            rows.append(row)
    return rows


def _metric(attempt_: Attempt, field: str, from_rest: bool) -> float:
    return getattr(attempt_.effort_from_rest if from_rest else attempt_.effort, field)


def _median(values: list[float]) -> float:
    return float(np.median(values)) if values else math.nan


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--goals", type=int, default=100, help="'ahead' goals (default 100)")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    parser.add_argument(
        "--variants",
        default=",".join(VARIANTS),
        help=f"comma-separated laws among {', '.join(VARIANTS)}",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = parser.parse_args(argv)
    names = args.variants.split(",")
    unknown = [name for name in names if name not in VARIANTS]
    if unknown or args.goals < 1 or args.workers < 1:
        print(
            f"studies.bench.input_change: unknown variants {unknown}, "
            "or --goals or --workers below 1",
            file=sys.stderr,
        )
        return 2
    found = measure(names, args.goals, args.workers)
    rows = summary(found, MobileManipulator.from_yaml(ROBOT_FILE).dof)
    if args.json:
        emit(json_text({"bench": "input_change", "goals": args.goals, "rows": rows}))
    else:
        shown = ("task", "law", "reached inside every limit", "nonzero moving", "nonzero last 2 s")
        emit(table([{k: row[k] for k in shown} for row in rows], floatfmt=".3g"))
        emit(
            table(
                [{k: v for k, v in row.items() if k not in shown[2:]} for row in rows],
                floatfmt=".3g",
            )
        )
    return 0


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
