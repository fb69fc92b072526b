"""`parsimony bench`: control-step times, the convergence test of section 6.3, goal shares."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from outputs.stdout import emit, json_text
from parsimony.argument_types import count
from profiles.deploy_files import ROBOT_FILE
from studies.benchmark import format_report, run_bench
from wbc.robot import MobileManipulator, RobotDescriptionError


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser("bench", help="time the control laws, measure goal shares")
    parser.add_argument("--repeats", type=int, default=2000, help="timed steps per law")
    parser.add_argument("--trials", type=int, default=50, help="repeats of the 6.3 pose task")
    parser.add_argument(
        "--goals", type=int, default=100, help="random goals per family and law (0: none)"
    )
    parser.add_argument("--robot", type=Path, default=ROBOT_FILE, help="robot description")
    parser.add_argument(
        "--zoo",
        nargs="+",
        type=Path,
        metavar="ROBOT",
        help="the robot descriptions timed law by law (default: every one of deploy/robots)",
    )
    parser.add_argument(
        "--zoo-only", action="store_true", help="only the step times of each robot (a quick run)"
    )
    parser.add_argument(
        "--runs",
        type=count("runs"),
        default=1,
        help="time the zoo this many times, robot after robot: each figure the runs' median, the "
        "glue's share of the LP step with its range",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    return parser


def run(args: argparse.Namespace) -> int:
    for path in args.zoo or ():  # a description that cannot be used stops the bench at once
        try:
            MobileManipulator.from_yaml(path)
        except RobotDescriptionError as error:
            print(f"parsimony bench: {error}", file=sys.stderr)
            return 2
    report = run_bench(
        args.repeats, args.trials, args.goals, args.robot, args.zoo, args.zoo_only, args.runs
    )
    emit(json_text(report, indent=2) if args.json else format_report(report))
    return 0
