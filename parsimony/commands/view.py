"""`parsimony view PROFILE`: a Foxglove live view of a running system (record.live_view): a
WebSocket server on 127.0.0.1 that Foxglove opens as a live source, until Ctrl-C or SIGTERM.
A replay into the profile's namespace is watched the same way."""

from __future__ import annotations

import argparse
import logging
import signal
import sys
from pathlib import Path

from components.rate_limited_log import RateLimitedLog
from deploy.query import QueryError, Target
from messages.topics import topics_matching
from parsimony.target_options import exit_code
from profiles.profile import ProfileError
from record.live_view import DEFAULT_PORT, LiveView


def port_number(text: str) -> int:
    """A TCP port, 0 to 65535 (0: any free port)."""
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a port number: {text!r}") from None
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"a port is from 0 to 65535, got {port}")
    return port


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser("view", help="a Foxglove live view of a running system",
                                   description=__doc__)  # fmt: skip
    parser.add_argument("profile", type=Path, help="deploy profile of the system")
    parser.add_argument("--port", type=port_number, default=DEFAULT_PORT,
                        help=f"on 127.0.0.1 (default {DEFAULT_PORT}, 0: any free one)")  # fmt: skip
    parser.add_argument("--keys", nargs="*", default=["*"], help="topic name patterns")
    return parser


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def run(args: argparse.Namespace) -> int:
    try:
        target = Target.from_profile(args.profile)
        chosen = topics_matching(args.keys)
    except (ProfileError, ValueError) as error:
        print(f"view: {error}", file=sys.stderr)
        return 2
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        warnings = RateLimitedLog(logging.getLogger("parsimony.view"))
        with target.open() as session, LiveView(session, target.namespace, chosen, args.port,
                                                warnings.warning) as view:  # fmt: skip
            try:
                print(f"view: {target.namespace} live at {view.address}", file=sys.stderr,
                      flush=True)  # fmt: skip
                while True:
                    signal.pause()
            except KeyboardInterrupt:
                pass
            print(f"view: {view.shown} messages shown, {view.malformed} malformed",
                  file=sys.stderr)  # fmt: skip
    except (QueryError, OSError) as error:
        print(f"view: {error}", file=sys.stderr)
        return exit_code(error)
    except KeyboardInterrupt:
        pass  # before the server was up
    finally:
        signal.signal(signal.SIGTERM, previous)
    return 0
