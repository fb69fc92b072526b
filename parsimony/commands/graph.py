"""`parsimony graph PROFILE`: which process publishes and subscribes to which key."""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

from launch.graph import dataflow
from outputs.stdout import emit, json_text
from profiles.profile import ProfileError, load_profile


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `graph` and its arguments."""
    parser = subparsers.add_parser(
        "graph",
        help="print the dataflow of a profile (text, JSON, Graphviz DOT or an image)",
        description="Derive the dataflow of a profile from what each component declares it "
        "reads and writes; nothing is started. Warns about topics read and never written.",
    )
    parser.add_argument("profile", type=Path, help="deploy profile (YAML)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of text")
    parser.add_argument("--dot", type=Path, metavar="FILE", help="also write Graphviz DOT here")
    parser.add_argument(
        "--png", type=Path, metavar="FILE", help="also draw it as PNG (needs Graphviz's dot)"
    )
    return parser


def run(args: argparse.Namespace) -> int:
    dot = shutil.which("dot") if args.png else None
    if args.png and dot is None:
        print(
            "graph: --png needs Graphviz's dot (install it: apt-get install graphviz, "
            "brew install graphviz); --dot FILE writes the graph without it",
            file=sys.stderr,
        )
        return 2
    try:
        graph = dataflow(load_profile(args.profile), args.profile)
    except (ProfileError, LookupError) as error:
        print(error, file=sys.stderr)
        return 2
    for warning in graph.warnings():
        print(warning, file=sys.stderr)
    emit(json_text(graph.to_json(), indent=2) if args.json else graph.to_text())
    if args.dot:
        args.dot.write_text(graph.to_dot() + "\n")
    if dot is not None:
        subprocess.run(
            [dot, "-Tpng", "-o", str(args.png)], input=graph.to_dot(), text=True, check=True
        )
    return 0
