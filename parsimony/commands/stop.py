"""`parsimony stop`: stop every motor of a namespace and keep it stopped until `parsimony
release` (the latched emergency stop, ``components.stop_latch``). The stop is put on
``control/stop`` as ``$PARSIMONY_USER``; the command then waits until every running component
that holds the latch (the drivers, the simulator, the controller, the supervisor) says in its
status that it holds this stop, and prints each. Exits 0 when each does, 1 when one does not in
``--timeout`` or none is running (or a release is refused: ``release_refusal``), 2 for input
that cannot be used or a router that cannot be reached.
"""

from __future__ import annotations

import argparse
import sys
import time

import zenoh

from components.stop_latch import release_refusal, stop_state, stop_text
from launch.query import QueryError, statuses
from messages import codec, topics
from messages.stop import StopState
from outputs.stdout import emit, json_text, table
from parsimony.target_options import EXIT_REFUSED, fail, profile_and_target, target_options
from profiles.access import tool_user
from profiles.profile import ProfileError

POLL_S = 0.05
"""How often the command asks the holders' statuses again while one has not taken it."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `stop` and its arguments."""
    return add_giver(
        subparsers,
        "stop",
        "stop every motor and keep it stopped until `parsimony release`",
        "Put the namespace in the stopped state: every driver and the simulator command zero "
        "at once and refuse motion, the controller and the supervisor hold, until `parsimony "
        "release`. A restarted component starts stopped. Anyone who may open a session may "
        "stop.",
    )


def add_giver(
    subparsers: argparse._SubParsersAction, name: str, help: str, description: str
) -> argparse.ArgumentParser:
    """A parser of `stop` or `release`: the target options and ``--reason``."""
    parser = subparsers.add_parser(
        name, parents=[target_options()], help=help, description=description
    )
    parser.add_argument("--reason", default="", help="why, as each component's status says it")
    return parser


def run(args: argparse.Namespace) -> int:
    return give(args, stopped=True)


def give(args: argparse.Namespace, stopped: bool) -> int:
    """Put the stop (or the release) and print which holders took it."""
    try:
        profile, target = profile_and_target(args)
        user = tool_user()
        refusal = None if stopped else release_refusal(profile, user)
        if refusal is not None:
            print(refusal, file=sys.stderr)
            return EXIT_REFUSED
        state = stop_state(stopped, user, args.reason)
        with target.open() as session:
            held = holders(session, profile.namespace, state, args.timeout)
    except (ProfileError, QueryError) as error:
        return fail(error)
    if not held:
        print(f"no component of {profile.namespace} holds the stop: none running", file=sys.stderr)
        return EXIT_REFUSED
    late = sorted(name for name, holds in held.items() if holds != state)
    if args.json:
        emit(
            json_text(
                {**state.model_dump(), "holders": {n: h.model_dump() for n, h in held.items()}}
            )
        )
    else:
        emit(
            table(
                [(name, stop_text(holds)) for name, holds in sorted(held.items())],
                ("NAME", "HOLDS"),
            )
        )
    if late:
        print(f"not taken in {args.timeout:g} s by: {', '.join(late)}", file=sys.stderr)
        return EXIT_REFUSED
    return 0


def holders(
    session: zenoh.Session, namespace: str, state: StopState, timeout_s: float
) -> dict[str, StopState]:
    """Put ``state`` on ``control/stop``, again while a running holder does not hold it (a
    holder takes a state once: a second put changes nothing where it was taken); the stop
    each holder holds once each holds ``state``, or at the timeout (then some hold another)."""
    deadline = time.monotonic() + timeout_s
    payload = codec.encode(state)
    while True:
        session.put(topics.CONTROL_STOP.key(namespace), payload)
        found = statuses(session, namespace, max(0.1, deadline - time.monotonic()))
        held = {name: s.stop for name, s in found.items() if s.stop is not None}
        if (held and all(h == state for h in held.values())) or time.monotonic() > deadline:
            return held
        time.sleep(POLL_S)
