"""How often the LP reaches the goals ahead, set by set, and why it misses the others.

Run as ``python -m studies.bench.goal_reach [--families 'A;B'] [--seeds 2,3,4] [--goals N]
[--variant 'gain=value,...']... [--supervised] [--workers W] [--json]``. Each family of
``studies.goal_families`` (the goals ahead by default: the bench's 'ahead' and issue 33's
two) is drawn from each seed (2 is the bench's; the default law's terms were tuned on seed 1),
and each law runs every goal as ``parsimony bench`` runs it (60 s at 50 Hz): the default LP,
each ``--variant`` (LPParams() with those gains changed, on the same goals) and, with
``--supervised``, the LP under the staging supervisor. Printed per set and law: the share
reached inside every limit and the median nonzero entries of u while moving; then per family
and law, over all its sets (the note on goal reach quotes these): the share reached, the worst
and the best set, the median nonzero entries while moving, and the goals missed: with the
goal's gripper within FOLDED m of its base (the arm bent back over it), with a joint at the
edge of the law's joint box (which), and with the base's heading more than HEADING_OFF from
the goal configuration's when the run ended.
"""

from __future__ import annotations

import argparse
import multiprocessing
import sys
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from outputs.stdout import emit, json_text, result_only_stdout, table
from profiles.deploy_files import ROBOT_FILE
from studies.goal_families import FAMILIES, goals
from studies.goal_sets import LAWS, SUPERVISED, Attempt, attempt, parsimony, shares
from wbc import dq
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.planar import wrap
from wbc.robot import MobileManipulator

AHEAD = ("ahead", "ahead, any arm start", "ahead, wide arm")
FOLDED = 0.2
"""A goal's gripper this near its base, horizontally (m), has the arm bent back over it."""
HEADING_OFF = 0.5
"""How far (rad) a missed run's base heading may end from the goal configuration's unremarked."""


def _attempt_one(job: tuple[str, dict[str, Any], Path, np.ndarray, np.ndarray]) -> Attempt:
    law, gains, robot_file, start, goal = job
    robot = MobileManipulator.from_yaml(robot_file)
    if law == SUPERVISED:
        return attempt(LAWS[SUPERVISED](robot), robot, start, goal, supervised=True)
    return attempt(LPLaw(robot, LPParams(**gains)), robot, start, goal)


def misses(
    pairs: list[tuple[np.ndarray, np.ndarray]], attempts: list[Attempt], robot: MobileManipulator
) -> dict[str, int]:
    """The goals not reached inside every limit, by kind (a goal may be of several)."""
    kinds: Counter[str] = Counter()
    for (_, goal), a in zip(pairs, attempts, strict=True):
        if a.within_all_limits:
            continue
        kinds["missed"] += 1
        gripper = dq.translation(robot.fkm(goal))[1:3]
        kinds["gripper over its base"] += bool(np.hypot(*(gripper - goal[:2])) < FOLDED)
        edge = a.reason.partition(", ")[2].removesuffix(" at the joint box's edge")
        kinds[f"{edge} at its box's edge"] += edge.startswith("q")
        turned = a.last is not None and abs(wrap(float(a.last[2] - goal[2]))) > HEADING_OFF
        kinds["base heading off"] += turned
    return {kind: n for kind, n in kinds.items() if n}


def measure(
    families: list[str],
    seeds: list[int],
    count: int,
    variants: dict[str, dict],
    supervised: bool,
    workers: int,
    robot_file: Path = ROBOT_FILE,
) -> dict:
    """Every law's attempts at every set: the rows per set, and the misses per family."""
    robot = MobileManipulator.from_yaml(robot_file)
    laws = list(variants.items())
    laws += [(SUPERVISED, {})] if supervised else []
    rows, missed = [], []
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        for family in families:
            found: dict[str, list[tuple]] = {name: [] for name, _ in laws}
            for seed in seeds:
                pairs = goals(FAMILIES[family], count, robot, seed)
                for name, gains in laws:
                    print(f"bench: {family}, seed {seed}, {name}", file=sys.stderr, flush=True)
                    jobs = [(name, gains, robot_file, start, goal) for start, goal in pairs]
                    attempts = pool.map(_attempt_one, jobs, chunksize=1)
                    found[name] += list(zip(pairs, attempts, strict=True))
                    rows.append(
                        {
                            "family": family,
                            "seed": seed,
                            "law": name,
                            "reached inside every limit": shares(attempts)[
                                "within_joint_and_speed_limits"
                            ],
                            "nonzero moving": parsimony(attempts, robot.dof)[
                                "median_nonzero_moving"
                            ],
                        }
                    )
            for name, runs in found.items():
                pairs, attempts = [run[0] for run in runs], [run[1] for run in runs]
                sets = [
                    row["reached inside every limit"]
                    for row in rows
                    if row["family"] == family and row["law"] == name
                ]
                missed.append(
                    {
                        "family": family,
                        "law": name,
                        "seeds": ",".join(map(str, seeds)),
                        "goals": len(runs),
                        "reached": shares(attempts)["within_joint_and_speed_limits"],
                        "worst set": min(sets),
                        "best set": max(sets),
                        "nonzero moving": parsimony(attempts, robot.dof)["median_nonzero_moving"],
                        **misses(pairs, attempts, robot),
                    }
                )
    return {"rows": rows, "misses": missed}


def variant(text: str) -> dict[str, Any]:
    """``'gain=value,...'`` as LPParams keywords (ValueError naming what is wrong)."""
    gains: dict[str, Any] = {}
    for item in filter(None, text.split(",")):
        name, equals, value = item.partition("=")
        if not equals:
            raise ValueError(f"expected gain=value, got {item!r}")
        try:
            gains[name.strip()] = float(value)
        except ValueError:
            gains[name.strip()] = {"true": True, "false": False}.get(value.strip(), value.strip())
    LPParams(**gains)  # refused here, with the gain named, before any run
    return gains


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--families",
        default=";".join(AHEAD),
        help="';'-separated families of studies.goal_families",
    )
    parser.add_argument("--seeds", default="2,3,4", help="comma-separated seeds (default 2,3,4)")
    parser.add_argument("--goals", type=int, default=100, help="goals per set (default 100)")
    parser.add_argument(
        "--variant",
        action="append",
        default=[],
        help="an LP with these gains changed, 'gain=value,...' (repeatable)",
    )
    parser.add_argument("--supervised", action="store_true", help="run the supervised LP too")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    args = parser.parse_args(argv)
    families = args.families.split(";")
    try:
        seeds = [int(seed) for seed in args.seeds.split(",")]
        variants = {"lp": {}, **{text: variant(text) for text in args.variant}}
    except (TypeError, ValueError) as error:
        print(f"studies.bench.goal_reach: {error}", file=sys.stderr)
        return 2
    unknown = [family for family in families if family not in FAMILIES]
    if unknown or args.goals < 1 or args.workers < 1:
        print(
            f"studies.bench.goal_reach: unknown families {unknown} (known: {'; '.join(FAMILIES)}), "
            "or --goals or --workers below 1",
            file=sys.stderr,
        )
        return 2
    report = measure(families, seeds, args.goals, variants, args.supervised, args.workers)
    if args.json:
        emit(json_text({"bench": "goal_reach", "goals": args.goals, **report}))
    else:
        emit(table(report["rows"], floatfmt=".3g"))
        emit(table(report["misses"], floatfmt=".3g"))
    return 0


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
