"""`parsimony topic list|info|echo|hz|pub`: the topics of a running system, decoded."""

from __future__ import annotations

import argparse
import json
import math
import sys
import threading
import time
from typing import Any

import numpy as np
import zenoh
from pydantic import BaseModel, ValidationError

from launch.graph import dataflow
from launch.query import QueryError, live_writers, overwritten_by
from launch.tool_clock import ToolClock
from messages import codec, topics
from outputs.stdout import emit, json_text
from parsimony.stop_signals import stop_signals
from parsimony.target_options import fail, profile_and_target, target_options
from profiles.profile import Profile, ProfileError

SOURCE = "parsimony"
"""The source named in the header of a message the command makes."""
NOTE_AFTER_S = 1.0
"""`echo` says what it waits for once this long has passed with no message."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `topic` and its actions."""
    parser = subparsers.add_parser("topic", help="list, describe, print, time or publish topics")
    common = target_options()
    actions = parser.add_subparsers(dest="action", required=True)
    actions.add_parser("list", parents=[common], help="every topic: key, type, who uses it")
    info = actions.add_parser("info", parents=[common], help="a topic's key, schema and users")
    # Its own copy of the common options: "resolve" takes --timeout out of the copy's action.
    echo = actions.add_parser(
        "echo",
        parents=[target_options()],
        conflict_handler="resolve",
        help="print each message, decoded",
    )
    echo.add_argument("--count", type=int, help="stop after this many messages")
    echo.add_argument(
        "--timeout",
        type=float,
        metavar="S",
        help="stop with exit 1 and 'no message in S s on TOPIC' when S seconds "
        "pass with no message (default: wait until --count or Ctrl-C)",
    )
    hz = actions.add_parser("hz", parents=[common], help="measure a topic's rate")
    hz.add_argument("--window", type=float, default=2.0, metavar="S", help="seconds to listen")
    pub = actions.add_parser("pub", parents=[common], help="publish a message given as JSON")
    for action in (info, echo, hz, pub):
        action.add_argument(
            "topic",
            choices=list(topics.TOPICS),
            metavar="TOPIC",
            help="a topic of the table: " + ", ".join(topics.TOPICS),
        )
    pub.add_argument(
        "message",
        help="the message's fields as JSON; a missing header is made, "
        "stamped on the profile's clock (the simulator's on a sim-clock profile)",
    )
    pub.add_argument("--count", type=int, default=1, help="how many times (default 1)")
    pub.add_argument("--rate", type=float, default=10.0, metavar="HZ")
    return parser


def printable(message: BaseModel) -> dict[str, Any]:
    """The message as JSON-ready fields; bytes (image data) shown by their length."""

    def shown(value: Any) -> Any:
        if isinstance(value, bytes):
            return f"<{len(value)} bytes>"
        if isinstance(value, dict):
            return {k: shown(v) for k, v in value.items()}
        if isinstance(value, list | tuple):
            return [shown(v) for v in value]
        return value

    return shown(message.model_dump())


def listen(
    session: zenoh.Session, key: str, topic: topics.Topic, until: threading.Event, on_message: Any
) -> zenoh.Subscriber:
    """Subscribe and hand each decoded message (or DecodeError) to ``on_message``."""

    def on_sample(sample: zenoh.Sample) -> None:
        if until.is_set():
            return
        try:
            on_message(codec.decode(sample.payload.to_bytes(), topic.type, key), time.monotonic())
        except codec.DecodeError as error:
            on_message(error, time.monotonic())

    return session.declare_subscriber(key, on_sample)


def run(args: argparse.Namespace) -> int:
    try:
        profile, target = profile_and_target(args)
        if args.action in ("list", "info"):
            graph = dataflow(profile)
            names = list(topics.TOPICS) if args.action == "list" else [args.topic]
            rows = [
                {
                    "topic": name,
                    "key": topics.TOPICS[name].key(profile.namespace),
                    "type": topics.TOPICS[name].type.__name__,
                    "max_bytes": topics.TOPICS[name].max_bytes,
                    "writers": graph.writers(name),
                    "readers": graph.readers(name),
                }
                for name in names
            ]
            if args.action == "info":
                rows[0]["schema"] = topics.TOPICS[args.topic].type.model_json_schema()
                emit(json_text(rows[0], indent=2))
            elif args.json:
                emit(json_text(rows, indent=2))
            else:
                emit(
                    "\n".join(
                        f"{r['key']:<34} {r['type']:<22} "
                        f"{', '.join(r['writers']) or '-'} -> "
                        f"{', '.join(r['readers']) or '-'}"
                        for r in rows
                    )
                )
            return 0
        if args.timeout is not None and not (math.isfinite(args.timeout) and args.timeout > 0):
            raise ValueError(
                f"--timeout: expected a finite number of seconds > 0, got {args.timeout}"
            )
        with target.open() as session:
            return {"echo": echo, "hz": hz, "pub": pub}[args.action](args, session, profile)
    except (ProfileError, QueryError, LookupError, ValueError) as error:
        return fail(error)


def echo(args: argparse.Namespace, session: zenoh.Session, profile: Profile) -> int:
    """Print each message as one line of JSON until --count of them, Ctrl-C, or --timeout
    seconds with no message (exit 1)."""
    topic = topics.TOPICS[args.topic]
    key = topic.key(profile.namespace)
    done = threading.Event()
    changed = threading.Condition()
    printed = 0

    def on_message(message: Any, _at: float) -> None:
        nonlocal printed
        with changed:
            if done.is_set():
                return
            if isinstance(message, codec.DecodeError):
                print(f"undecodable: {message}", flush=True, file=sys.stderr)
                return
            emit(json_text(printable(message)))
            printed += 1
            if args.count is not None and printed >= args.count:
                done.set()
            changed.notify_all()

    with stop_signals(raising=True), listen(session, key, topic, done, on_message), changed:
        seen, since, noted = 0, time.monotonic(), False
        try:
            while not done.is_set():
                silent_s = time.monotonic() - since
                if args.timeout is not None and silent_s >= args.timeout:
                    done.set()
                    print(f"no message in {args.timeout:g} s on {key}", file=sys.stderr)
                    return 1
                if not noted and printed == 0 and silent_s >= NOTE_AFTER_S:
                    noted = True
                    print(f"waiting for messages on {key} (Ctrl-C to stop)", file=sys.stderr)
                limits = [args.timeout - silent_s] if args.timeout is not None else []
                limits += [] if noted else [NOTE_AFTER_S - silent_s]
                changed.wait(max(0.0, min(limits)) if limits else None)
                if printed != seen:
                    seen, since = printed, time.monotonic()
        except KeyboardInterrupt:
            done.set()
    return 0


def hz(args: argparse.Namespace, session: zenoh.Session, profile: Profile) -> int:
    """Listen for --window seconds; print the rate and the periods' median, min, max."""
    topic = topics.TOPICS[args.topic]
    arrivals: list[float] = []
    done = threading.Event()
    with listen(
        session, topic.key(profile.namespace), topic, done, lambda message, at: arrivals.append(at)
    ):
        time.sleep(args.window)
        done.set()
    periods = np.diff(arrivals)
    report = {
        "topic": args.topic,
        "messages": len(arrivals),
        "window_s": args.window,
        "rate_hz": len(arrivals) / args.window,
        "period_median_s": float(np.median(periods)) if len(periods) else math.nan,
        "period_min_s": float(periods.min()) if len(periods) else math.nan,
        "period_max_s": float(periods.max()) if len(periods) else math.nan,
    }
    if args.json:
        emit(json_text(report))
    else:
        emit(
            f"{args.topic}: {report['rate_hz']:.1f} Hz over {args.window} s "
            f"({len(arrivals)} messages), period median {report['period_median_s']:.4f} s, "
            f"min {report['period_min_s']:.4f}, max {report['period_max_s']:.4f}"
        )
    return 0 if arrivals else 1


def pub(args: argparse.Namespace, session: zenoh.Session, profile: Profile) -> int:
    """Validate the JSON as the topic's message (a header is made if missing, stamped on the
    profile's clock) and publish it; warn when a running component of the profile writes the
    topic too (it overwrites what is published here)."""
    topic = topics.TOPICS[args.topic]
    key = topic.key(profile.namespace)
    try:
        fields = json.loads(args.message)
    except json.JSONDecodeError as error:
        raise ValueError(f"message: not JSON ({error})") from None
    writers = live_writers(session, profile, args.topic, args.timeout)
    if writers:
        print(f"warning: {overwritten_by(writers, key)}", file=sys.stderr)
    publisher = session.declare_publisher(key)
    deadline = time.monotonic() + max(args.timeout, 2.0)
    while not publisher.matching_status.matching and time.monotonic() < deadline:
        time.sleep(0.01)
    with ToolClock(session, profile) as clock:
        for seq in range(args.count):
            values = dict(fields)
            if "header" in topic.type.model_fields and "header" not in values:
                values["header"] = clock.header(seq, SOURCE, args.timeout).model_dump()
            try:
                message = topic.type.model_validate(values)
            except ValidationError as error:
                raise ValueError(
                    f"{args.topic}: {error.errors()[0]['loc']}: {error.errors()[0]['msg']}"
                ) from None
            publisher.put(codec.encode(message))
            if seq + 1 < args.count:
                time.sleep(1.0 / args.rate)
    emit(
        json_text(
            {
                "topic": args.topic,
                "published": args.count,
                "subscribers": publisher.matching_status.matching,
                "live_writers": writers,
            }
        )
    )
    publisher.undeclare()
    return 0
