"""`parsimony launch PROFILE`: start and supervise every component of a profile."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path

import zenoh

from deploy.graph import dataflow
from deploy.launcher import Launcher
from deploy.zenoh_error import zenoh_error_text
from profiles.profile import ProfileError, load_profile

EXIT_INVALID_PROFILE = 2


def positive(what: str) -> Callable[[str], float]:
    """An argument type: a finite number > 0 of ``what`` (``nan``, ``inf`` and ``-1`` are
    refused, saying what was expected)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
        if not math.isfinite(value) or value <= 0.0:
            raise argparse.ArgumentTypeError(f"expected a finite number of {what} > 0, "
                                             f"got {text!r}")  # fmt: skip
        return value

    parse.__name__ = what  # argparse names the type in its own messages
    return parse


positive_seconds = positive("seconds")
"""A duration in seconds."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `launch` and its arguments."""
    parser = subparsers.add_parser(
        "launch",
        help="start and supervise the components of a profile",
        description="Open the profile's router, start one process per enabled component, "
        "stream their logs, restart them by policy, stop them in order on Ctrl-C. "
        "Exits 0, 1 if a component failed, 2 if the profile is invalid.",
    )
    parser.add_argument("profile", type=Path, help="deploy profile (YAML)")
    parser.add_argument(
        "--duration", type=positive_seconds, metavar="S", help="stop everything after S seconds"
    )
    return parser


def run(args: argparse.Namespace) -> int:
    """Validate the profile, then launch it until stopped."""
    try:
        profile = load_profile(args.profile)
        graph = dataflow(profile, args.profile)
    except (ProfileError, LookupError) as error:
        print(error, file=sys.stderr)
        return EXIT_INVALID_PROFILE
    launcher = Launcher(profile, args.profile)
    for warning in graph.warnings():
        launcher.output.say(warning)
    try:
        return launcher.run(args.duration)
    except zenoh.ZError as error:
        print(f"{args.profile}: cannot open the router: {zenoh_error_text(error)}",
              file=sys.stderr)  # fmt: skip
        return 1
