"""`parsimony view PROFILE`: a Foxglove live view and control station of a running system
(view.live_view, view.control_station): a WebSocket server on 127.0.0.1 that Foxglove opens as a
live source, until Ctrl-C or SIGTERM (or ``--duration S``). It draws the robot of the profile's
description, lets its clients send goals on goal/request (when the user may write it) and set
any running component's parameters. A replay into the profile's namespace is watched the same
way (``--namespace NS``: a replay into a namespace of its own). It runs ``--nice`` steps below
the loop's priority (10 by default), so that on a busy machine the loop takes the CPU first.
``--layout FILE`` writes the Foxglove layout of the namespace (``parsimony layout``); ``--json``
prints what the view did when it stops (messages, the handler's times, the goals sent, refused
and dropped, the station's errors), as it says on stderr. It exits 1 when the station's Zenoh
session failed and no new one could be opened."""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path

import zenoh

from components.rate_limited_log import RateLimitedLog
from launch.query import QueryError, Target
from messages.topics import Topic, check_namespace, topics_matching
from outputs.stdout import emit, json_text
from parsimony.argument_types import positive_seconds
from parsimony.stop_signals import STOP_SIGNALS, stop_signals
from parsimony.target_options import exit_code
from profiles.profile import Profile, ProfileError, load_profile
from ros2.urdf import assets as urdf_assets
from scenes.foxglove_views import Viewer
from view.control_station import ControlStation
from view.live_view import DEFAULT_PORT, LiveView
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


def namespace_argument(text: str) -> str:
    """A namespace a key can start with (``topics.check_namespace``), else an argument error."""
    try:
        return check_namespace(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "view", help="a Foxglove live view and control station", description=__doc__
    )
    parser.add_argument("profile", type=Path, help="deploy profile of the system")
    parser.add_argument(
        "--port",
        type=port_number,
        default=DEFAULT_PORT,
        help=f"on 127.0.0.1 (default {DEFAULT_PORT}, 0: any free one)",
    )
    parser.add_argument("--keys", nargs="*", default=["*"], help="topic name patterns")
    parser.add_argument(
        "--namespace",
        type=namespace_argument,
        help="watch this namespace instead of the profile's (a replay's)",
    )
    parser.add_argument("--layout", type=Path, help="write the Foxglove layout to this file")
    parser.add_argument("--force", action="store_true", help="write over an existing layout")
    parser.add_argument(
        "--nice",
        type=int,
        default=NICE,
        choices=range(0, 20),
        metavar="N",
        help=f"run N steps below the loop's priority (default {NICE})",
    )
    parser.add_argument(
        "--duration", type=positive_seconds, metavar="S", help="stop after S seconds"
    )
    parser.add_argument(
        "--json", action="store_true", help="when it stops, print what it did as JSON"
    )
    return parser


NICE = 10
"""How far below the loop's CPU priority the view runs: on a busy machine the loop's components
take the CPU first, and the view falls behind and sheds rather than slow them."""


def run(args: argparse.Namespace) -> int:
    try:
        profile = watched_profile(load_profile(args.profile), args.namespace)
        chosen = topics_matching(args.keys)
        robot = MobileManipulator.from_yaml(profile.robot) if profile.robot else None
        if args.layout is not None:
            # Foxglove's layouts library is imported only by a view that writes one.
            from parsimony.commands.layout import write_layout

            names = robot.joint_names if robot else ()
            write_layout(profile.namespace, args.layout, args.force, names)
    except (ProfileError, ValueError, OSError) as error:
        print(f"view: {error}", file=sys.stderr)
        return 2
    target = Target(profile.namespace, profile.zenoh)
    os.nice(args.nice)
    with stop_signals((*STOP_SIGNALS, signal.SIGALRM)) as stop:
        if args.duration is not None:
            signal.setitimer(signal.ITIMER_REAL, args.duration)
        try:
            with (
                target.open() as session,
                serving(session, profile, chosen, args.port, robot) as (view, station),
            ):
                live(view, station)
                stop.wait()
                return stopped(view, station, args.json)
        except (QueryError, OSError) as error:
            print(f"view: {error}", file=sys.stderr)
            return exit_code(error)
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)


def watched_profile(profile: Profile, namespace: str | None) -> Profile:
    """``profile`` with the namespace watched (and given goals) in place of its own, if given."""
    return profile if namespace is None else profile.model_copy(update={"namespace": namespace})


@contextlib.contextmanager
def serving(
    session: zenoh.Session,
    profile: Profile,
    chosen: Sequence[Topic],
    port: int,
    robot: MobileManipulator | None,
) -> Iterator[tuple[LiveView, ControlStation]]:
    """The live view and control station of ``profile``'s namespace on ``session``, served on
    127.0.0.1:``port`` (``parsimony view``'s, ``replay --view``'s); ``live`` says so."""
    warnings = RateLimitedLog(logging.getLogger("parsimony.view"))
    station = ControlStation(session, profile)
    try:
        with LiveView(
            session,
            profile.namespace,
            chosen,
            port,
            warnings.warning,
            Viewer(robot),
            station,
            station.capabilities,
            station.encodings,
            assets=None if robot is None else urdf_assets(robot),
        ) as view:
            station.attach(view.server)
            yield view, station
    finally:
        station.close()


def live(view: LiveView, station: ControlStation) -> None:
    """Say on stderr where the view is live and what its clients may do."""
    publishing = (
        "goals from clients on goal/request"
        if station.may_publish
        else (f"no publishing: {station.user} may not write goal/request")
    )
    setting = "" if station.may_set_any else f", read-only: {station.user} may set none"
    print(
        f"view: {station.namespace} live at {view.address} ({publishing}; the "
        f"parameters of every running component{setting})",
        file=sys.stderr,
        flush=True,
    )


def stopped(view: LiveView, station: ControlStation, as_json: bool) -> int:
    """Say on stderr what the view and its station did (as JSON on stdout if ``as_json``);
    1 if the station's Zenoh session failed and no new one could be opened, else 0."""
    handler = view.handler_us()
    done = {
        "goals_sent": station.goals_sent,
        "goals_refused": station.goals_refused,
        "goals_dropped": station.goals_dropped,
        "session_errors": station.session_errors,
        "errors": station.errors,
    }
    print(
        f"view: {view.shown} messages shown, {view.malformed} malformed, {view.unwatched} "
        f"read by no client, {view.failed} without views; handler "
        f"{handler['median']} us median, {handler['p99']} us p99 over {handler['samples']}; "
        f"{station.goals_sent} goals sent, {station.goals_refused} refused, "
        f"{station.goals_dropped} dropped over their rate; {station.session_errors} Zenoh "
        f"session errors, {station.errors} errors answering clients",
        file=sys.stderr,
    )
    if station.failed:
        print(f"view: {station.failed}", file=sys.stderr)
    if as_json:
        emit(
            json_text(
                {
                    "shown": view.shown,
                    "unwatched": view.unwatched,
                    "malformed": view.malformed,
                    "failed": view.failed,
                    "handler_us": handler,
                    **done,
                    "session_failed": station.failed or None,
                }
            )
        )
    return 1 if station.failed else 0
