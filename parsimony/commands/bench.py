"""`parsimony bench`: control-step times and the convergence test of section 6.3."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from parsimony.benchmark import ROBOT_FILE, format_report, run_bench


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser("bench", help="time the control laws (JSON and a table)")
    parser.add_argument("--repeats", type=int, default=2000, help="timed steps per law")
    parser.add_argument("--trials", type=int, default=50, help="repeats of the 6.3 pose task")
    parser.add_argument("--goals", type=int, default=20, help="random goals for success rates")
    parser.add_argument("--robot", type=Path, default=ROBOT_FILE, help="robot description")
    parser.add_argument("--json-out", type=Path, help="also write the JSON report here")
    return parser


def run(args: argparse.Namespace) -> int:
    report = run_bench(args.repeats, args.trials, args.goals, args.robot)
    print(json.dumps(report))
    print(format_report(report))
    if args.json_out:
        args.json_out.write_text(json.dumps(report, indent=2))
    return 0
