"""`parsimony reproduce`: every result of chapter 6 beside ours (see parsimony.reproduce)."""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict
from pathlib import Path

from deploy import ROBOT_FILE
from parsimony.output import emit, json_text
from parsimony.reproduce import TRIALS, format_laws, format_rows, reproduce, write_figures
from wbc.robot import MobileManipulator


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "reproduce", help="run chapter 6's set-ups kinematically and print each result beside "
                          "the dissertation's")  # fmt: skip
    parser.add_argument("--out", type=Path, default=Path("runs/reproduce"),
                        help="where the figures go (default runs/reproduce)")
    parser.add_argument("--trials", type=int, default=TRIALS,
                        help=f"trials of each law in each test of 6.3 (default {TRIALS}; the "
                             "dissertation ran 10,000)")  # fmt: skip
    parser.add_argument("--robot", type=Path, default=ROBOT_FILE, help="robot description")
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    return parser


def run(args: argparse.Namespace) -> int:
    if args.trials < 1:
        print(f"parsimony reproduce: --trials must be at least 1, got {args.trials}",
              file=sys.stderr)  # fmt: skip
        return 2
    robot = MobileManipulator.from_yaml(args.robot)
    rows, laws, found = reproduce(robot, args.trials)
    figures = write_figures(robot, found, args.out)
    print(f"reproduce: {len(figures)} figures and notes in {args.out}", file=sys.stderr)
    if args.json:
        emit(json_text({"laws": laws, "rows": [asdict(row) for row in rows],
                         "figures": [str(path) for path in figures]}))  # fmt: skip
    else:
        emit(format_laws(laws) + "\n\n" + format_rows(rows))
    return 0
