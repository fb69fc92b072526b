"""The hyper-redundant question over the zoo: nonzero entries of u against the robot's DOF.

Run as ``python -m studies.bench.redundancy [--robots NAME,...] [--goals N] [--seed S]
[--workers W] [--time-limit S] [--families pose,position] [--figure PNG]``: every robot
of deploy/robots (or those named), LP, QP and pseudoinverse on its pose and position goals
(or those of ``--families``; ``studies.redundancy``). The
report is JSON on stdout; progress and the table go to stderr. ``--from REPORT.json ...``
reads reports this command printed (one per robot, say) instead of running, and prints them
merged, with their table and figure.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from matplotlib.figure import Figure

from outputs.stdout import emit, json_text, result_only_stdout, table
from profiles.deploy_files import zoo
from studies import redundancy
from studies.redundancy import TASKS

STYLE = {"pinv": ("tab:red", 5.0), "qp": ("tab:orange", 2.5), "lp": ("tab:blue", 1.5)}
"""Each law's colour and line width, drawn in this order (wide under narrow: they overlap)."""


def entries(robot: dict) -> int:
    """The entries of u a robot of the report can move: all of them, but the base's three on
    a fixed base (a differential base's x' and y' are two entries of one velocity)."""
    return robot["arm_dof"] if robot["base"] == "fixed" else robot["dof"]


def rows(report: dict) -> list[dict]:
    """The table: a row per robot, family and law."""
    found = []
    for name, robot in sorted(report["robots"].items(), key=lambda item: entries(item[1])):
        for family, laws in robot["families"].items():
            for law, row in laws.items():
                found.append(
                    {
                        "robot": name,
                        "base": robot["base"],
                        "dof": robot["dof"],
                        "entries": entries(robot),
                        "goals": family,
                        "task dof": TASKS[family],
                        "law": law,
                        "reached in limits": row["reached_within_limits"],
                        "reached": row["reached"],
                        "nonzero moving": row["nonzero_moving"],
                        "nonzero near": row["nonzero_near"],
                        "engaged moving": row["engaged_moving"],
                        "engaged near": row["engaged_near"],
                        "<= task + engaged": row["within_bound"],
                    }
                )
    return found


def figure(report: dict, path: Path) -> Path:
    """Median nonzero entries of u (moving: solid, near the goal: dotted) against the entries
    the robot can move (``entries``), a line per law, a panel per family; grey: every entry,
    and the task's DOF."""
    robots = sorted(report["robots"].values(), key=entries)
    dofs = [entries(robot) for robot in robots]
    fig = Figure(figsize=(9.0, 3.4), layout="constrained")
    for index, (family, task_dof) in enumerate(TASKS.items()):
        axes = fig.add_subplot(1, len(TASKS), index + 1)
        axes.plot(dofs, dofs, color="0.7", linewidth=3, label="every entry")
        axes.axhline(task_dof, color="0.7", linestyle="--", label="task DOF")
        for law, (colour, width) in STYLE.items():
            for part, line in (("moving", "-"), ("near", ":")):
                values = [robot["families"][family][law][f"nonzero_{part}"] for robot in robots]
                axes.plot(
                    dofs,
                    values,
                    line,
                    marker="o",
                    color=colour,
                    linewidth=width,
                    alpha=0.8,
                    label=f"{law}, {part}",
                )
        axes.set_title(f"{family} goals (task DOF {task_dof})")
        axes.set_xlabel("entries of u the robot can move")
        axes.set_ylabel("median nonzero entries of u")
        axes.set_xticks(dofs)
        axes.grid(alpha=0.3)
    fig.legend(*axes.get_legend_handles_labels(), fontsize=7, loc="outside right center")
    fig.savefig(path, dpi=72)
    return path


def merged(paths: list[Path]) -> dict:
    """Reports this command printed, as one (their robots and families together)."""
    report: dict = {"robots": {}}
    for path in paths:
        part = json.loads(path.read_text())
        robots = report["robots"]
        for name, robot in part["robots"].items():
            families = {**robots.get(name, {}).get("families", {}), **robot["families"]}
            robots[name] = {**robot, "families": families}
        report = {**part, "robots": robots}
    return report


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", help="comma-separated description names (default: the zoo)")
    parser.add_argument("--goals", type=int, default=redundancy.GOALS, help="goals per robot")
    parser.add_argument("--seed", type=int, default=redundancy.SEED, help="the goals' seed")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    parser.add_argument(
        "--time-limit",
        type=float,
        default=redundancy.TIME_LIMIT_S,
        help=f"seconds a run may take (default {redundancy.TIME_LIMIT_S:g})",
    )
    parser.add_argument(
        "--families", default=",".join(TASKS), help="comma-separated: pose, position (both)"
    )
    parser.add_argument("--figure", type=Path, help="write the figure (PNG) here")
    parser.add_argument("--from", dest="reports", type=Path, nargs="+", help="reports to merge")
    args = parser.parse_args(argv)
    known = {path.stem: path for path in zoo()}
    names = args.robots.split(",") if args.robots else list(known)
    unknown = [name for name in names if name not in known]
    families = tuple(args.families.split(","))
    unknown += [family for family in families if family not in TASKS]
    if unknown or args.goals < 1 or args.workers < 1 or not args.time_limit > 0.0:
        print(
            f"studies.bench.redundancy: unknown robots or families {unknown} (known: "
            f"{', '.join(known)}; {', '.join(TASKS)}), "
            "or --goals or --workers below 1, or --time-limit not above 0",
            file=sys.stderr,
        )
        return 2
    if args.reports:
        try:
            report = merged(args.reports)
        except (OSError, ValueError, KeyError) as error:
            print(f"studies.bench.redundancy: not a report: {error}", file=sys.stderr)
            return 2
    else:
        report = {
            "study": "redundancy",
            "seed": args.seed,
            "goals": args.goals,
            "time_limit_s": args.time_limit,
            "robots": redundancy.study(
                [known[name] for name in names],
                args.goals,
                args.workers,
                args.seed,
                args.time_limit,
                families,
            ),
        }
    print(table(rows(report), floatfmt=".2f"), file=sys.stderr)
    if args.figure:
        redundancy.progress(f"figure {figure(report, args.figure)}")
    emit(json_text(report))
    return 0


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
