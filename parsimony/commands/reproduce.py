"""`parsimony reproduce`: every result of chapter 6 beside ours (see studies.reproduce);
with ``--loop``, the rows of 6.2 also on the whole simulated loop (studies.reproduce.loop)."""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict
from pathlib import Path

from launch.query import QueryError
from outputs.stdout import emit, json_text
from parsimony.argument_types import count
from parsimony.commands.experiment import time_limit
from profiles.deploy_files import ROBOT_FILE
from profiles.profile import ProfileError, load_profile
from studies.experiment import PROFILES, TIME_LIMIT_S
from studies.reproduce import NAMES, TRIALS, format_laws, format_rows, reproduce, write_figures
from studies.reproduce.loop import LABELS, LOOP_LAWS, beside, loop, summary_line
from wbc.robot import MobileManipulator


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "reproduce",
        help="run chapter 6's set-ups kinematically (with --loop, on the whole "
        "simulated loop too) and print each result beside the "
        "dissertation's",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("runs/reproduce"),
        help="where the figures go, and the loop's runs in OUT/loop (default runs/reproduce)",
    )
    parser.add_argument(
        "--trials",
        type=count("trials"),
        default=TRIALS,
        help=f"trials of each law in each test of 6.3 (default {TRIALS}; the "
        "dissertation ran 10,000)",
    )
    parser.add_argument("--robot", type=Path, default=ROBOT_FILE, help="robot description")
    parser.add_argument(
        "--only",
        choices=NAMES,
        action="append",
        metavar="SET-UP",
        help=f"only this set-up ({', '.join(NAMES)}; repeatable): its rows, "
        "figures and loop runs; section 6.3's timed tests run with all "
        "of them",
    )
    parser.add_argument(
        "--loop",
        action="store_true",
        help="also run the set-ups of 6.2 (pose, position, obstacle) on the "
        "whole simulated loop in lockstep, vision in the loop, and print "
        "the same rows of each recording beside the kinematic "
        "ones",
    )
    parser.add_argument(
        "--law",
        choices=LABELS,
        action="append",
        metavar="LABEL",
        help="with --loop, run only this law on the loop (repeatable): " + "; ".join(LABELS),
    )
    parser.add_argument(
        "--time-limit",
        type=time_limit,
        default=TIME_LIMIT_S,
        metavar="S",
        help="with --loop, simulated seconds before a run that has not "
        f"converged stops (default {TIME_LIMIT_S:g})",
    )
    parser.add_argument(
        "--no-figures",
        dest="figures",
        action="store_false",
        help="the rows alone: draw no figures (nor NOTES.md), the loop's runs none either",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    return parser


def usage_error(args: argparse.Namespace) -> str | None:
    """Why the arguments cannot run, or None."""
    if args.law and not args.loop:
        return "--law chooses the laws of the loop: add --loop"
    if args.loop:
        profile_robot = load_profile(PROFILES["lp"]).robot
        if args.robot.resolve() != profile_robot.resolve():
            return (
                f"--loop runs the robot of {PROFILES['lp'].name} ({profile_robot}), not "
                f"{args.robot}"
            )
        if not set(args.only or NAMES) & set(LOOP_LAWS):
            return f"--loop runs {', '.join(LOOP_LAWS)} of 6.2; --only chose none of them"
    return None


def run(args: argparse.Namespace) -> int:
    error = usage_error(args)
    if error is not None:
        print(f"parsimony reproduce: {error}", file=sys.stderr)
        return 2
    robot = MobileManipulator.from_yaml(args.robot)
    names = tuple(name for name in NAMES if name in (args.only or NAMES))
    rows, laws, found = reproduce(robot, args.trials, names)
    figures = write_figures(robot, found, args.out) if args.figures else []
    if figures:
        print(f"reproduce: {len(figures)} figures and notes in {args.out}", file=sys.stderr)
    ran = None
    if args.loop:
        try:
            loop_rows, loop_laws, ran = loop(
                robot,
                names,
                tuple(args.law or LABELS),
                args.out / "loop",
                args.time_limit,
                args.figures,
            )
        except (ProfileError, OSError, QueryError, RuntimeError, ValueError) as error:
            print(f"parsimony reproduce: the loop: {error}", file=sys.stderr)
            return 1
        rows, laws = beside(rows, loop_rows), laws + loop_laws
    if args.json:
        emit(
            json_text(
                {
                    "laws": laws,
                    "rows": [asdict(row) for row in rows],
                    "figures": [str(path) for path in figures],
                }
                | ({"loop": ran} if ran else {})
            )
        )
    else:
        emit(
            format_laws(laws)
            + "\n\n"
            + format_rows(rows)
            + (f"\n\n{summary_line(ran)}" if ran else "")
        )
    return 0
