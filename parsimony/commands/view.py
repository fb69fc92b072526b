"""`parsimony view PROFILE`: a Foxglove live view and control station of a running system
(record.live_view, deploy.control_station): a WebSocket server on 127.0.0.1 that Foxglove
opens as a live source, until Ctrl-C or SIGTERM. It draws the robot of the profile's
description, lets its clients send goals on goal/request (when the user may write it) and set
any running component's parameters. A replay into the profile's namespace is watched the same
way. It runs ``--nice`` steps below the loop's priority (10 by default), so that on a busy
machine the loop takes the CPU first. ``--layout FILE`` writes the Foxglove layout of the
namespace (``parsimony layout``); ``--json`` prints what the view did when it stops (messages,
the handler's times)."""

from __future__ import annotations

import argparse
import logging
import os
import signal
import sys
from pathlib import Path

from components.rate_limited_log import RateLimitedLog
from deploy.control_station import ControlStation
from deploy.query import QueryError, Target
from messages.topics import topics_matching
from parsimony.commands.layout import write_layout
from parsimony.output import emit, json_text
from parsimony.target_options import exit_code
from profiles.profile import ProfileError, load_profile
from record.foxglove_views import Viewer
from record.live_view import DEFAULT_PORT, LiveView
from wbc.robot import MobileManipulator


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
    parser = subparsers.add_parser("view", help="a Foxglove live view and control station",
                                   description=__doc__)  # fmt: skip
    parser.add_argument("profile", type=Path, help="deploy profile of the system")
    parser.add_argument("--port", type=port_number, default=DEFAULT_PORT,
                        help=f"on 127.0.0.1 (default {DEFAULT_PORT}, 0: any free one)")  # fmt: skip
    parser.add_argument("--keys", nargs="*", default=["*"], help="topic name patterns")
    parser.add_argument("--layout", type=Path, help="write the Foxglove layout to this file")
    parser.add_argument("--force", action="store_true", help="write over an existing layout")
    parser.add_argument("--nice", type=int, default=NICE, choices=range(0, 20), metavar="N",
                        help=f"run N steps below the loop's priority (default {NICE})")
    parser.add_argument("--json", action="store_true", help="print what it did, as JSON")
    return parser


NICE = 10
"""How far below the loop's CPU priority the view runs: on a busy machine the loop's components
take the CPU first, and the view falls behind and sheds rather than slow them."""


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def run(args: argparse.Namespace) -> int:
    try:
        profile = load_profile(args.profile)
        chosen = topics_matching(args.keys)
        robot = MobileManipulator.from_yaml(profile.robot) if profile.robot else None
        if args.layout is not None:
            write_layout(profile.namespace, args.layout, args.force)
    except (ProfileError, ValueError, OSError) as error:
        print(f"view: {error}", file=sys.stderr)
        return 2
    target = Target(profile.namespace, profile.zenoh)
    os.nice(args.nice)
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        warnings = RateLimitedLog(logging.getLogger("parsimony.view"))
        with target.open() as session:
            station = ControlStation(session, profile)
            try:
                with LiveView(session, target.namespace, chosen, args.port, warnings.warning,
                              Viewer(robot), station, station.capabilities,
                              station.encodings) as view:  # fmt: skip
                    station.attach(view.server)
                    _serve(view, station, target.namespace, args.json)
            finally:
                station.close()
    except (QueryError, OSError) as error:
        print(f"view: {error}", file=sys.stderr)
        return exit_code(error)
    except KeyboardInterrupt:
        pass  # before the server was up
    finally:
        signal.signal(signal.SIGTERM, previous)
    return 0


def _serve(view: LiveView, station: ControlStation, namespace: str, as_json: bool) -> None:
    """Serve until interrupted, then say what the view did."""
    publishing = "goals from clients on goal/request" if station.may_publish else (
        f"no publishing: {station.user} may not write goal/request")  # fmt: skip
    print(f"view: {namespace} live at {view.address} ({publishing}; the parameters of every "
          f"running component)", file=sys.stderr, flush=True)  # fmt: skip
    try:
        while True:
            signal.pause()
    except KeyboardInterrupt:
        pass
    handler = view.handler_us()
    print(f"view: {view.shown} messages shown, {view.malformed} malformed, {view.unwatched} "
          f"read by no client, {view.failed} without views; handler "
          f"{handler['median']} us median, {handler['p99']} us p99 over {handler['samples']}; "
          f"{station.goals_sent} goals sent", file=sys.stderr)  # fmt: skip
    if as_json:
        emit(json_text({"shown": view.shown, "unwatched": view.unwatched,
                         "malformed": view.malformed, "failed": view.failed,
                         "handler_us": handler, "goals_sent": station.goals_sent}))  # fmt: skip
