"""How a component process runs: ``python -m components.<module> --profile P --name N``.

Every component module ends with ``run_component(MyComponent)``. It parses the command line
of ``messages.process.command``, loads the profile, builds the ``Node`` (a profile or
parameter it cannot use exits with ``EXIT_CONFIG_ERROR``, never restarted), starts the
component and runs until SIGINT, SIGTERM or the end of its launcher.
"""

from __future__ import annotations

import argparse
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
    PARAMS_FILE_ENV,
    PARENT_PID_ENV,
    parent_gone,
)
from profiles.profile import ProfileError, load_profile

log = logging.getLogger("components")


class _StopRequested(Exception):
    """Raised in the main thread by SIGINT or SIGTERM."""


def _on_stop_signal(signum: int, _frame: object) -> None:
    for stop_signal in (signal.SIGINT, signal.SIGTERM):
        signal.signal(stop_signal, signal.SIG_IGN)
    raise _StopRequested(signal.Signals(signum).name)


def _wait_for_stop(node: Node) -> None:
    """Sleep until a stop signal, the node's ``fail``, or the end of the launcher that
    started us."""
    while not node.stop_requested.wait(1.0):
        if parent_gone():
            log.warning("launcher (pid %s) is gone; stopping", os.environ[PARENT_PID_ENV])
            return


def _parse_args(component_class: type[Component], argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=component_class.__doc__)
    parser.add_argument("--profile", required=True, help="the deploy profile (YAML)")
    parser.add_argument("--name", required=True, help="this component's name in the profile")
    parser.add_argument("--log-level", default="INFO", help="DEBUG, INFO, WARNING or ERROR")
    return parser.parse_args(argv)


def _configure(component_class: type[Component], args: argparse.Namespace) -> Node | None:
    """The component's node, or ``None`` after logging why the configuration is refused."""
    try:
        profile = load_profile(args.profile)
    except ProfileError as error:
        log.error("%s", error)
        return None
    names = [spec.name for spec in profile.components]
    if args.name not in names:
        log.error("%s: no component named %r (have %s)", args.profile, args.name, names)
        return None
    try:
        kept = os.environ.get(PARAMS_FILE_ENV)
        return Node(
            profile,
            args.name,
            component_class.params,
            component_class.reads,
            component_class.writes,
            Path(kept) if kept else None,
        )
    except ParamError as error:
        log.error("%s: components[%d].params.%s", args.profile, names.index(args.name), error)
        return None


def main(component_class: type[Component], argv: Sequence[str] | None = None) -> int:
    """Run ``component_class`` until SIGINT or SIGTERM; return the exit code."""
    args = _parse_args(component_class, argv)
    logging.basicConfig(
        level=args.log_level.upper(), stream=sys.stderr, format="%(levelname)s %(message)s"
    )
    for stop_signal in (signal.SIGINT, signal.SIGTERM):
        signal.signal(stop_signal, _on_stop_signal)
    node = None
    try:
        node = _configure(component_class, args)
        if node is None:
            return EXIT_CONFIG_ERROR
        with node:
            try:
                component = component_class(node)
            except ParamError as error:
                log.error("%s: %s: %s", args.profile, args.name, error)
                return EXIT_CONFIG_ERROR
            node.start(component.shutdown, component.clock_stalled)
            _wait_for_stop(node)
    except _StopRequested as stop:
        log.info("%s stopping on %s", args.name, stop)
    except zenoh.ZError as error:
        log.error("%s: Zenoh failed: %s", args.name, error)
        return 1
    return EXIT_FOR_GOOD if node is not None and node.failure is not None else 0


def run_component(component_class: type[Component]) -> NoReturn:
    """The entry point of every component module: run it and exit with its code."""
    sys.exit(main(component_class))
