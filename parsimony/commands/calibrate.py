"""`parsimony calibrate camera`: the ceiling camera's intrinsics from views of a ChArUco board."""

from __future__ import annotations

import argparse
import sys


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser("calibrate", help="calibrate the ceiling camera")
    steps = parser.add_subparsers(dest="step", required=True)
    steps.add_parser("camera", help="intrinsics from views of a ChArUco board")
    return parser


def run(args: argparse.Namespace) -> int:
    print("calibrate: not built yet", file=sys.stderr)
    return 2
