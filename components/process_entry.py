"""How a component process runs: ``python -m components.<module> --profile P --name N``.

Every component module ends with ``run_component(MyComponent)``. It parses the command line
of ``messages.process.command``, loads the profile, builds the ``Node`` (a profile or
parameter it cannot use exits with ``EXIT_CONFIG_ERROR``, never restarted), starts the
component and runs until SIGINT, SIGTERM or the end of its launcher.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import os
import signal
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

import zenoh

from components.params import ParamError
from components.runtime import Component, Node
from messages.process import (
    EXIT_CONFIG_ERROR,
    EXIT_FOR_GOOD,
    PARENT_PID_ENV,
    params_file,
    parent_gone,
)
from profiles.profile import ProfileError, load_profile

log = logging.getLogger("components")


class StopRequested(BaseException):
    """Raised in the main thread by SIGINT or SIGTERM. Not an ``Exception``, as
    ``KeyboardInterrupt`` is not: a handler of errors (logging's, which prints "--- Logging
    error ---" and goes on) would otherwise swallow it when the signal lands inside a log call,
    and the stop would be lost (its signals are ignored from then on)."""


def _on_stop_signal(signum: int, _frame: object) -> None:
    for stop_signal in (signal.SIGINT, signal.SIGTERM):
        signal.signal(stop_signal, signal.SIG_IGN)
    raise StopRequested(signal.Signals(signum).name)


def _wait_for_stop(nodes: Sequence[Node]) -> None:
    """Sleep until a stop signal, the ``fail`` of one of ``nodes``, or the end of the launcher
    that started us."""
    first, poll_s = nodes[0], 1.0 if len(nodes) == 1 else 0.1
    while not first.stop_requested.wait(poll_s):
        if any(node.stop_requested.is_set() for node in nodes):
            return
        if parent_gone():
            log.warning("launcher (pid %s) is gone; stopping", os.environ[PARENT_PID_ENV])
            return


def _parse_args(component_class: type[Component], argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=component_class.__doc__)
    parser.add_argument("--profile", required=True, help="the deploy profile (YAML)")
    parser.add_argument("--name", required=True, help="this component's name in the profile")
    parser.add_argument("--log-level", default="INFO", help="DEBUG, INFO, WARNING or ERROR")
    return parser.parse_args(argv)


def _configure(
    component_class: type[Component],
    profile_path: str,
    name: str,
    params_file: Path | None,
    session: zenoh.Session | None = None,
) -> Node | None:
    """The component's node, or ``None`` after logging why the configuration is refused."""
    try:
        profile = load_profile(profile_path)
    except ProfileError as error:
        log.error("%s", error)
        return None
    names = [spec.name for spec in profile.components]
    if name not in names:
        log.error("%s: no component named %r (have %s)", profile_path, name, names)
        return None
    try:
        return Node(
            profile,
            name,
            component_class.params,
            component_class.reads,
            component_class.writes,
            params_file,
            session,
        )
    except ParamError as error:
        log.error("%s: components[%d].params.%s", profile_path, names.index(name), error)
        return None


def start_logging(level: str) -> None:
    """Log to stderr at ``level``, and stop on SIGINT and SIGTERM (``StopRequested``)."""
    logging.basicConfig(level=level.upper(), stream=sys.stderr, format="%(levelname)s %(message)s")
    for stop_signal in (signal.SIGINT, signal.SIGTERM):
        signal.signal(stop_signal, _on_stop_signal)


TX_QUEUE_KEY = "transport/link/tx/queue/size/data"
"""A link's queue of data batches (Zenoh's default 2, at most 16): full, a sample waits a
millisecond, then is dropped."""


def _shared_session(profile_path: str, members: int) -> zenoh.Session | None:
    """One session for the ``members`` components of this process: a sample one of them
    publishes reaches the others in the process without a copy on the network; each of its
    links queues what the links of their sessions each queued (a recorder starved of CPU
    once lost 0.4 s of a lockstep run's commands behind the default). None (a session each)
    when the components authenticate, each as its name (``zenoh.access``), or are clients."""
    try:
        zenoh_settings = load_profile(profile_path).zenoh
    except ProfileError:
        return None  # each component's configuration says why
    if zenoh_settings.access is not None or zenoh_settings.mode == "client":
        return None
    config = zenoh_settings.component_config()
    queued = json.loads(config.get_json(TX_QUEUE_KEY))
    config.insert_json5(TX_QUEUE_KEY, json.dumps(min(16, queued * members)))
    return zenoh.open(config)


def serve(profile_path: str, members: Sequence[tuple[type[Component], str, Path | None]]) -> int:
    """Run each ``(component class, name, kept parameters file)`` of ``members`` in this
    process, started in order and closed in the reverse order, until a stop signal or one's
    ``fail``; the exit code (``start_logging`` first)."""
    nodes: list[Node] = []
    name = ""
    try:
        with contextlib.ExitStack() as stack:
            session = _shared_session(profile_path, len(members)) if len(members) > 1 else None
            if session is not None:
                stack.callback(session.close)  # once every node has closed
            for component_class, name, params_file in members:
                node = _configure(component_class, profile_path, name, params_file, session)
                if node is None:
                    return EXIT_CONFIG_ERROR
                stack.enter_context(node)
                nodes.append(node)
                try:
                    component = component_class(node)
                except ParamError as error:
                    log.error("%s: %s: %s", profile_path, name, error)
                    return EXIT_CONFIG_ERROR
                node.start(component.shutdown, component.clock_stalled)
            _wait_for_stop(nodes)
    except StopRequested as stop:
        names = ", ".join(node.name for node in nodes) or name
        log.info("%s stopping on %s", names, stop)
    except zenoh.ZError as error:
        log.error("%s: Zenoh failed: %s", name, error)
        return 1
    return EXIT_FOR_GOOD if any(node.failure is not None for node in nodes) else 0


def main(component_class: type[Component], argv: Sequence[str] | None = None) -> int:
    """Run ``component_class`` until SIGINT or SIGTERM; return the exit code."""
    args = _parse_args(component_class, argv)
    start_logging(args.log_level)
    return serve(args.profile, [(component_class, args.name, params_file(args.name))])


def run_component(component_class: type[Component]) -> NoReturn:
    """The entry point of every component module: run it and exit with its code."""
    sys.exit(main(component_class))
