"""`parsimony replay FILE`: a recorded session back into Zenoh, with its recorded timing.

Messages go out as recorded, headers unchanged, spaced by their recorded log times divided by
``--rate``; ``--sensors`` sends only what a robot's sensors send (the camera, the odometry, the
joint states), so that a live tracker, estimator and controller run again on recorded inputs;
``--clock`` also publishes ``sim/clock`` at the recorded times, for components on simulated
time. Progress goes to stderr; ``--start-paused`` waits for Enter first.
"""

from __future__ import annotations

import argparse
import fnmatch
import sys
import time
from pathlib import Path

import zenoh

from deploy.query import QueryError
from messages import codec, topics
from messages.clock import Clock
from parsimony.commands.launch import positive_seconds
from parsimony.target_options import fail, profile_and_target, target_options
from profiles.profile import ProfileError
from record.session_file import read_session

SENSORS = ("camera/image", "base/odometry", "arm/joint_states")
"""What ``--sensors`` replays: the inputs a robot's drivers and camera give."""
CLOCK_PERIOD_NS = 10_000_000
"""``--clock`` publishes sim/clock at most this often (recorded time)."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "replay", parents=[target_options()], help="publish a recorded session again",
        description=__doc__.split("\n\n")[1],
    )  # fmt: skip
    parser.add_argument("file", type=Path, help="MCAP session")
    parser.add_argument("--rate", type=positive_seconds, default=1.0, help="speed factor")
    parser.add_argument("--loop", action="store_true", help="start again at the end")
    parser.add_argument("--start-offset", type=float, default=0.0, metavar="S")
    parser.add_argument("--duration", type=positive_seconds, metavar="S")
    parser.add_argument("--keys", nargs="*", default=["*"], help="topic name patterns to send")
    parser.add_argument("--exclude", nargs="*", default=[], help="topic name patterns to skip")
    parser.add_argument("--namespace", help="publish under this namespace instead")
    parser.add_argument("--sensors", action="store_true", help="only " + ", ".join(SENSORS))
    parser.add_argument("--clock", action="store_true", help="publish sim/clock as recorded")
    parser.add_argument("--start-paused", action="store_true", help="wait for Enter")
    return parser


def wanted(args: argparse.Namespace, name: str) -> bool:
    if args.sensors and name not in SENSORS:
        return False
    if any(fnmatch.fnmatch(name, p) for p in args.exclude):
        return False
    return any(fnmatch.fnmatch(name, p) for p in args.keys)


def run(args: argparse.Namespace) -> int:
    try:
        profile, target = profile_and_target(args)
        session = target.open()
    except (ProfileError, QueryError) as error:
        return fail(error)
    namespace = args.namespace or profile.namespace
    try:
        topics.check_namespace(namespace)
        records = [r for r in read_session(args.file)
                   if r.topic_name is not None and r.message is not None
                   and wanted(args, r.topic_name)]  # fmt: skip
    except (OSError, ValueError) as error:
        session.close()
        return fail(error)
    if not records:
        session.close()
        return fail(ValueError(f"{args.file}: nothing to replay"))
    with session:
        publishers: dict[str, zenoh.Publisher] = {}
        if args.start_paused:
            print("[replay] paused: press Enter to start", file=sys.stderr, flush=True)
            sys.stdin.readline()
        while True:
            sent = replay_once(args, records, session, namespace, publishers)
            print(f"[replay] {sent} messages sent", file=sys.stderr, flush=True)
            if not args.loop:
                return 0


def replay_once(args, records, session, namespace, publishers) -> int:
    """One pass over ``records`` at the recorded pace; the number of messages sent."""
    first = records[0].log_time_ns + round(args.start_offset * 1e9)
    last = first + round(args.duration * 1e9) if args.duration else None
    started, sent, clock_ns, shown = time.monotonic(), 0, None, 0.0
    for record in records:
        if record.log_time_ns < first or (last is not None and record.log_time_ns > last):
            continue
        due = started + (record.log_time_ns - first) / 1e9 / args.rate
        pause = due - time.monotonic()
        if pause > 0:
            time.sleep(pause)  # the recorded gap, scaled: this is the replay's clock
        if args.clock and (clock_ns is None or record.log_time_ns - clock_ns >= CLOCK_PERIOD_NS):
            clock_ns = record.log_time_ns
            publish(session, publishers, topics.SIM_CLOCK.key(namespace),
                    Clock(stamp_ns=clock_ns))  # fmt: skip
        topic = topics.TOPICS[record.topic_name]
        publish(session, publishers, topic.key(namespace), record.message)
        sent += 1
        now = time.monotonic()
        if now - shown >= 1.0:
            done = (record.log_time_ns - first) / 1e9
            print(f"[replay] {done:7.2f} s  {sent} messages", file=sys.stderr, flush=True)
            shown = now
    return sent


def publish(session, publishers: dict, key: str, message) -> None:
    """Publish as recorded: the header is the recorded one (verbatim)."""
    if key not in publishers:
        publishers[key] = session.declare_publisher(key)
    publishers[key].put(codec.encode(message))
