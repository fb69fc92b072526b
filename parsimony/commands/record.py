"""`parsimony record PROFILE -o FILE`: every message of a running system into an MCAP file,
until Ctrl-C, SIGINT or SIGTERM (the recorder component of components.recorder, run as a child
that stops with this process); or `--recover FILE -o OUT`: a whole file from what survives of
one whose recorder was killed. An existing output is refused unless ``--force``; the input of
``--recover`` never is its output. Exit 2 when the router cannot be reached."""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
from pathlib import Path

from launch.query import QueryError, Target
from messages.process import PARENT_PID_ENV
from messages.topics import topics_matching
from outputs.files import writable_output, written_whole
from outputs.stdout import emit
from parsimony.memory_file import memory_file
from profiles.profile import ProfileError
from profiles.recorder import RECORDER, with_recorder


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "record", help="record a running system to MCAP", description=__doc__
    )
    parser.add_argument("profile", type=Path, nargs="?", help="deploy profile of the system")
    parser.add_argument("-o", "--output", type=Path, required=True, help="the MCAP file")
    parser.add_argument("--keys", nargs="*", default=["*"], help="topic name patterns")
    parser.add_argument("--recover", type=Path, metavar="FILE", help="a killed recording")
    parser.add_argument("--force", action="store_true", help="replace an existing output")
    return parser


def run(args: argparse.Namespace) -> int:
    problem = writable_output(args.output, [args.recover] if args.recover else [], args.force)
    if problem:
        print(f"record: {problem}", file=sys.stderr)
        return 2
    if args.recover is not None:
        # The MCAP reader (and Foxglove's schemas) only for a recovery, not for every recording.
        from record.session_reader import recover

        try:
            with written_whole(args.output) as partial:
                saved = recover(args.recover, partial)
        except OSError as error:
            print(f"record: {error}", file=sys.stderr)
            return 2
        emit(f"{saved} messages saved to {args.output}")
        return 0
    if args.profile is None:
        print("record: a profile, or --recover FILE", file=sys.stderr)
        return 2
    try:
        topics_matching(args.keys)
    except ValueError as error:
        print(f"record: {error}", file=sys.stderr)
        return 2
    try:
        Target.from_profile(args.profile).open().close()  # the router must be there
    except (ProfileError, QueryError) as error:
        print(f"record: {error}", file=sys.stderr)
        return 2
    return record(with_recorder(args.profile, args.output, args.keys))


def record(profile: str) -> int:
    """Run the recorder of ``profile`` (YAML text) until it stops; SIGINT and SIGTERM are
    passed on to it (it writes all that waits, then its footer), and it stops by itself if
    this process dies (it watches its parent, ``PARENT_PID_ENV``). The profile is a
    ``memory_file`` the child inherits."""
    descriptor, path = memory_file("record.yaml", profile)
    command = [
        sys.executable,
        "-m",
        "components.recorder",
        "--profile",
        str(path),
        "--name",
        RECORDER,
    ]
    env = {**os.environ, PARENT_PID_ENV: str(os.getpid())}
    process = subprocess.Popen(command, env=env, start_new_session=True, pass_fds=(descriptor,))
    os.close(descriptor)

    def pass_on(signum: int, _frame: object) -> None:
        process.send_signal(signal.SIGTERM)

    previous = {s: signal.signal(s, pass_on) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        return process.wait()
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
