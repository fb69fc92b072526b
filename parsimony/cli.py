"""The `parsimony` command: one subcommand per module of `parsimony.commands`."""

from __future__ import annotations

import argparse
import importlib
import sys

from parsimony.output import result_only_stdout

COMMANDS = (
    "demo", "experiment", "bench", "launch", "status", "param", "node", "topic", "graph", "schema",
    "record", "info", "replay", "rerun", "report", "view", "reproduce",
)  # fmt: skip


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="parsimony", description=__doc__)
    subparsers = parser.add_subparsers(dest="command", required=True)
    for name in COMMANDS:
        module = importlib.import_module(f"parsimony.commands.{name}")
        module.add_parser(subparsers).set_defaults(run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    with result_only_stdout():
        return int(args.run(args) or 0)


if __name__ == "__main__":
    sys.exit(main())
