"""`parsimony demo`: the closed-loop kinematic demo (see studies.kinematic_demo)."""

from __future__ import annotations

import argparse
from pathlib import Path

from outputs.stdout import emit, json_text
from profiles.deploy_files import ROBOT_FILE
from studies.kinematic_demo import format_table, run_demo


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo", help="run the LP and cascade laws on the chapter 6 tasks, kinematically"
    )
    parser.add_argument("--robot", type=Path, default=ROBOT_FILE, help="robot description")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    return parser


def run(args: argparse.Namespace) -> int:
    rows = run_demo(args.robot)
    emit(json_text(rows, indent=2) if args.json else format_table(rows))
    expected = all(
        row["converged"] != (row["law"] in ("LP conservative",))
        for row in rows
        if row["experiment"] != "joint limit"
    )
    return 0 if expected else 1
