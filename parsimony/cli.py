"""The `parsimony` command: one subcommand per module of `parsimony.commands`."""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from mcap.exceptions import McapError

from launch.query import QueryError
from outputs.stdout import result_only_stdout
from parsimony.target_options import exit_code

COMMANDS = (
    "demo",
    "experiment",
    "bench",
    "launch",
    "status",
    "param",
    "node",
    "topic",
    "goal",
    "graph",
    "schema",
    "record",
    "info",
    "replay",
    "rerun",
    "report",
    "export",
    "view",
    "layout",
    "reproduce",
    "calibrate",
    "study",
    "doctor",
    "stop",
    "release",
    "teleop",
)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """Every command's parser; with ``command``, only that command's module is imported (each
    pulls in what it runs on: the laws, the plots, the components) and the others are named."""
    parser = argparse.ArgumentParser(prog="parsimony", description=__doc__)
    subparsers = parser.add_subparsers(dest="command", required=True)
    for name in COMMANDS:
        if command in (None, name):
            module = importlib.import_module(f"parsimony.commands.{name}")
            module.add_parser(subparsers).set_defaults(run=module.run)
        else:
            subparsers.add_parser(name)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one command. A file it cannot read or write, a file that is not what it should be
    (``McapError``) and a router it cannot reach end it with one line and exit 2, a question
    the running system did not answer with exit 1 (``target_options.exit_code``), never a
    traceback; a reader of its output that went away (``| head``) ends it quietly."""
    words = sys.argv[1:] if argv is None else argv
    chosen = next((word for word in words if not word.startswith("-")), None)
    args = build_parser(chosen if chosen in COMMANDS else None).parse_args(words)
    try:
        with result_only_stdout():
            return int(args.run(args) or 0)
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no error at exit
        return 1
    except (OSError, McapError, QueryError) as error:
        print(f"parsimony {args.command}: {error}", file=sys.stderr)
        return exit_code(error)


if __name__ == "__main__":
    sys.exit(main())
