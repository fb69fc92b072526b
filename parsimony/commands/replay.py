"""`parsimony replay FILE`: a recorded session back into Zenoh, with its recorded timing.

Messages go out as recorded, headers unchanged, spaced by their recorded log times divided by
``--rate`` (those of one time sensors first, camera, joints, odometry); ``--sensors`` sends
only what a robot's sensors send (the camera, the joint states, the odometry), so that a live
tracker, estimator and controller run again on recorded inputs; ``--clock`` also publishes
``sim/clock`` at the recorded times, for components on simulated time; ``--lockstep`` waits
after each camera frame and odometry message until the live tracker and estimator have
answered it, as the simulator's lockstep waits for its loop, so that they take a lockstep
recording's inputs in its recorded order whatever the load. Progress goes to stderr. In a
terminal, keys: space pauses and resumes, ``s`` or the right arrow sends the next message
while paused, ``+`` and ``-`` double and halve the rate, ``q`` quits; ``--start-paused``
starts paused (elsewhere it waits for Enter). Without a profile it replays into the namespace
it was recorded in, through the launcher's default router (tcp/127.0.0.1:7447). With no system
running (no router answers on that loopback endpoint) the replay serves a router of its own
there, which `parsimony view` of a profile on it reaches; ``--view`` serves that live view
itself (on ``--port``). What is stamped far outside the session (``record.session_span``) is
not sent, and said.

Into a namespace where components are alive, a replay refuses, before it sends anything, to
send commands (live drivers would move the robot) and any topic a live component publishes
(two sources of one topic: a second clock, a second truth), unless ``--into-live``; a
namespace of its own (``--namespace``) is the safe way. The engine is ``record.replayer``.
"""

from __future__ import annotations

import argparse
import contextlib
import fnmatch
import math
import sys
from pathlib import Path

import zenoh

from launch.graph import component_class
from launch.query import NoRouter, QueryError, Target, live_components
from launch.zenoh_error import zenoh_error_text
from messages import topics
from parsimony.argument_types import positive, positive_seconds
from parsimony.commands.view import (
    live,
    namespace_argument,
    port_number,
    serving,
    stopped,
    watched_profile,
)
from parsimony.stop_signals import Interrupted, stop_signals
from parsimony.target_options import fail, target_options
from profiles.endpoints import endpoint_problem
from profiles.profile import Profile, ProfileError, load_profile
from record.replay_keys import terminal_keys
from record.replayer import ANSWER_TIMEOUT_S, ANSWERING, SENSORS, Player, Playing, Recording
from view.live_view import DEFAULT_PORT
from wbc.robot import MobileManipulator

COMMANDS = (topics.BASE_COMMAND.name, topics.ARM_COMMAND.name)
"""What moves a robot: never replayed into a namespace where anything is alive, unless
``--into-live``."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "replay",
        parents=[target_options()],
        help="publish a recorded session again",
        description=__doc__.split("\n\n")[1],
    )
    parser.add_argument("file", type=Path, help="MCAP session")
    parser.add_argument(
        "--rate", type=positive("times the recorded speed"), default=1.0, help="speed factor"
    )
    parser.add_argument("--loop", action="store_true", help="start again at the end")
    parser.add_argument(
        "--start-offset",
        type=float,
        default=0.0,
        metavar="S",
        help="start S s after the recording's first message",
    )
    parser.add_argument(
        "--duration",
        type=positive_seconds,
        metavar="S",
        help="send S s of the recording (default: to its end)",
    )
    parser.add_argument("--keys", nargs="*", default=["*"], help="topic name patterns to send")
    parser.add_argument("--exclude", nargs="*", default=[], help="topic name patterns to skip")
    parser.add_argument(
        "--namespace",
        type=namespace_argument,
        help="publish under this namespace instead of the recorded one (or --profile's)",
    )
    parser.add_argument("--sensors", action="store_true", help="only " + ", ".join(SENSORS))
    parser.add_argument("--clock", action="store_true", help="publish sim/clock as recorded")
    parser.add_argument(
        "--lockstep",
        action="store_true",
        help="wait for the live tracker's and estimator's answers",
    )
    parser.add_argument(
        "--answer-timeout",
        type=positive_seconds,
        default=ANSWER_TIMEOUT_S,
        help=f"seconds --lockstep waits for an answer before it goes on (default "
        f"{ANSWER_TIMEOUT_S:g})",
    )
    parser.add_argument(
        "--start-paused",
        action="store_true",
        help="start paused (in a terminal), else wait for Enter",
    )
    parser.add_argument(
        "--into-live", action="store_true", help="send commands, and topics live components publish"
    )
    parser.add_argument(
        "--view",
        action="store_true",
        help="serve a Foxglove live view of the replay, as parsimony view "
        "(needs --profile: the robot it draws)",
    )
    parser.add_argument(
        "--port",
        type=port_number,
        default=DEFAULT_PORT,
        help=f"--view's port on 127.0.0.1 (default {DEFAULT_PORT}, 0: any free)",
    )
    return parser


def wanted(args: argparse.Namespace, name: str) -> bool:
    if args.sensors and name not in SENSORS:
        return False
    if any(fnmatch.fnmatch(name, p) for p in args.exclude):
        return False
    return any(fnmatch.fnmatch(name, p) for p in args.keys)


def run(args: argparse.Namespace) -> int:
    """Replay as asked until the end, ``q``, or a stop signal (SIGINT or SIGTERM, whatever the
    process inherited: ``parsimony.stop_signals``), which ends it with 128 plus its number."""
    with stop_signals(raising=True):
        try:
            return replay(args)
        except Interrupted as stop:
            print(f"\n[replay] interrupted by {stop.signal}", file=sys.stderr, flush=True)
            return stop.exit_code


def replay(args: argparse.Namespace) -> int:
    """The replay ``args`` ask for, and what it did said on stderr (the view's too)."""
    try:  # what was asked is checked before the router is reached
        recorded = recording(args)
        profile = load_profile(args.profile) if args.profile is not None else None
        namespace = args.namespace or (profile.namespace if profile else recorded.namespace())
        if args.view and profile is None:
            raise ValueError(
                "--view: give the --profile the view draws the robot and takes "
                "goals as (or use parsimony view PROFILE)"
            )
        watched = watched_profile(profile, namespace) if profile else None
        robot = MobileManipulator.from_yaml(profile.robot) if args.view and profile.robot else None
        target = Target(namespace, profile.zenoh) if profile else Target.from_namespace(namespace)
        session, own_router = opened(target)
    except (ProfileError, QueryError, OSError, ValueError) as error:
        print("replay: ", end="", file=sys.stderr)
        return fail(error)
    if recorded.outside is not None:
        print(f"[replay] not sent, {recorded.outside}", file=sys.stderr)
    with session:
        conflicts = (
            []
            if args.into_live or own_router
            else live_conflicts(session, profile, namespace, recorded.names)
        )
        if conflicts:
            print(
                f"replay: refused: {'; '.join(conflicts)}. Replay into a namespace of its own "
                "(--namespace), leave those topics out (--exclude, --sensors), or say "
                "--into-live",
                file=sys.stderr,
            )
            return 2
        view = (
            serving(session, watched, topics.topics_matching(["*"]), args.port, robot)
            if watched and args.view
            else contextlib.nullcontext()
        )
        return played(args, session, namespace, recorded, view)


def played(
    args: argparse.Namespace,
    session: zenoh.Session,
    namespace: str,
    recorded: Recording,
    view: contextlib.AbstractContextManager,
) -> int:
    """The replay on ``session`` (``view``: its live view, or nothing); once the view has said
    it is live, it says what it did when the replay ends, whatever ends it."""
    playing = Playing(
        args.rate,
        args.start_offset,
        args.duration,
        args.loop,
        args.clock,
        args.lockstep,
        args.start_paused,
        args.answer_timeout,
    )
    try:
        with view as served:
            try:
                if served is not None:
                    live(*served)
                with terminal_keys() as keys:
                    return Player(playing, session, namespace, recorded, keys).run()
            finally:
                if served is not None:
                    stopped(*served, as_json=False)
    except OSError as error:  # the view's port
        print(f"replay: {error}", file=sys.stderr)
        return 2


def recording(args: argparse.Namespace) -> Recording:
    """What the replay sends, checked against what was asked (``ValueError`` saying why)."""
    if not math.isfinite(args.start_offset) or args.start_offset < 0:
        raise ValueError(f"--start-offset: expected seconds >= 0, got {args.start_offset}")
    topics.topics_matching(args.keys)
    recorded = Recording.of(args.file, lambda name: wanted(args, name))
    if not recorded.names:
        raise ValueError(f"{args.file}: nothing to replay (--keys, --exclude, --sensors)")
    first, last = recorded.window(args.start_offset, args.duration)
    if first > last:
        raise ValueError(
            f"{args.file}: nothing in the window of --start-offset and "
            f"--duration (the recording spans "
            f"{(recorded.end_ns - recorded.start_ns) / 1e9:.2f} s)"
        )
    if args.lockstep and ANSWERING.keys() & recorded.names:
        raise ValueError(
            f"--lockstep: the replay would answer itself; leave out "
            f"{', '.join(ANSWERING)} (or use --sensors)"
        )
    return recorded


def opened(target: Target) -> tuple[zenoh.Session, bool]:
    """A session on the target's router, and False; or, when none answers and the router's
    endpoints are on this host, a router of the replay's own listening there (a launcher's,
    without uplinks, so only local tools reach it), and True."""
    try:
        return target.open(), False
    except NoRouter as error:
        if any(endpoint_problem(e, needs_port=True) for e in target.zenoh.router):
            raise
        settings = target.zenoh.model_copy(update={"uplinks": []})
        try:
            session = zenoh.open(settings.router_config(target.namespace))
        except zenoh.ZError as failed:
            raise NoRouter(
                f"{error}; nor could the replay's own router listen there: "
                f"{zenoh_error_text(failed)}"
            ) from failed
    where = ", ".join(target.zenoh.router)
    print(
        f"[replay] no router at {where} (no system running): the replay serves its own "
        f"there, into {target.namespace}; `parsimony view` of a profile on it watches it",
        file=sys.stderr,
        flush=True,
    )
    return session, True


def live_conflicts(
    session: zenoh.Session, profile: Profile | None, namespace: str, sending: set[str]
) -> list[str]:
    """What the replay may not send into ``namespace``: commands while anything there is alive,
    and each topic a live component publishes (a live component the profile, if any, does not
    describe might publish any). Empty when nothing there is alive."""
    alive = live_components(session, namespace)
    if not alive:
        return []
    found = []
    if moving := sorted(sending & set(COMMANDS)):
        found.append(f"{', '.join(moving)} into {namespace}, where {', '.join(alive)} are alive")
    for name in alive:
        specs = profile.components if profile and namespace == profile.namespace else []
        spec = next((s for s in specs if s.name == name), None)
        if spec is None:
            writes = set(topics.TOPICS)  # not described: it may publish anything
        else:
            writes = {spec.topic(t).name for t in component_class(spec).writes}
        if clash := sorted((sending & writes) - set(COMMANDS)):
            found.append(f"{', '.join(clash)}, which the live {name} publishes")
    return found
