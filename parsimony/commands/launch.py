"""`parsimony launch PROFILE`: start and supervise every component of a profile; with
``--record FILE``, and a recorder that writes every topic to FILE (``parsimony record``'s)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import zenoh

from launch.graph import dataflow
from launch.launcher import Launcher
from launch.zenoh_error import zenoh_error_text
from outputs.files import writable_output
from parsimony.argument_types import positive_seconds
from parsimony.memory_file import memory_file
from profiles.profile import Profile, ProfileError, load_profile
from profiles.recorder import RECORDER, with_recorder

EXIT_INVALID_PROFILE = 2


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `launch` and its arguments."""
    parser = subparsers.add_parser(
        "launch",
        help="start and supervise the components of a profile",
        description="Open the profile's router, start one process per enabled component, "
        "stream their logs, restart them by policy, stop them in order on Ctrl-C. "
        "With --record FILE, a recorder writes every topic to FILE: it starts first, the "
        "others once it is alive, and it stops last, writing all that still waits. "
        "Exits 0, 1 if a component failed, 2 if the profile or FILE cannot be used.",
    )
    parser.add_argument("profile", type=Path, help="deploy profile (YAML)")
    parser.add_argument(
        "--duration", type=positive_seconds, metavar="S", help="stop everything after S seconds"
    )
    parser.add_argument(
        "--record",
        type=Path,
        metavar="FILE",
        help="record every topic to this MCAP file (see parsimony info FILE)",
    )
    parser.add_argument("--force", action="store_true", help="with --record, replace FILE")
    return parser


def run(args: argparse.Namespace) -> int:
    """Validate the profile (and the recording's file), then launch it until stopped."""
    problem = args.record and writable_output(args.record, [args.profile], args.force)
    if problem:
        print(f"launch: {problem}", file=sys.stderr)
        return EXIT_INVALID_PROFILE
    try:
        profile = load_profile(args.profile)
        graph = dataflow(profile, args.profile)  # warnings of its own, not of a recorder's
        launched, path, fds = profile, args.profile, ()
        if args.record:
            check_records_nothing(profile, args.profile)
            descriptor, path = memory_file("launch.yaml", with_recorder(args.profile, args.record))
            launched, fds = load_profile(path), (descriptor,)
    except (ProfileError, LookupError) as error:
        print(error, file=sys.stderr)
        return EXIT_INVALID_PROFILE
    launcher = Launcher(launched, path, pass_fds=fds)
    for warning in graph.warnings():
        launcher.output.say(warning)
    if args.record:
        launcher.output.say(f"recording every topic to {args.record}")
    try:
        code = launcher.run(args.duration)
    except zenoh.ZError as error:
        print(f"{args.profile}: cannot open the router: {zenoh_error_text(error)}", file=sys.stderr)
        return 1
    if args.record and args.record.exists():
        launcher.output.say(f"recorded to {args.record}; see parsimony info {args.record}")
    return code


def check_records_nothing(profile: Profile, path: Path) -> None:
    """``ProfileError`` if ``profile`` already runs a recorder, or a component of the name
    ``--record`` gives its own: one recording, to the file the user named."""
    for spec in profile.start_order():
        if spec.role == "recorder":
            raise ProfileError(
                f"{path}: already records (its component {spec.name!r} writes "
                f"{spec.params.get('path', 'session.mcap')}); launch it without "
                "--record"
            )
        if spec.name == RECORDER:
            raise ProfileError(
                f"{path}: its component {RECORDER!r} is a {spec.role}, and "
                "--record adds a recorder of that name; rename it"
            )
