"""`parsimony status`: the live components of a namespace and their counters."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from deploy.query import (
    DEFAULT_ROUTER,
    DEFAULT_TIMEOUT_S,
    QueryError,
    Target,
    live_components,
    statuses,
)
from messages.status import ComponentStatus
from parsimony.output import emit, json_text, table
from parsimony.target_options import fail
from profiles.profile import ProfileError

COLUMNS = ("NAME", "MODULE", "STATE", "PID", "COUNTERS (non-zero)")


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `status` and its arguments."""
    parser = subparsers.add_parser(
        "status",
        help="list the live components of a namespace",
        description="List the components whose liveliness token is present, with their "
        "state and counters. Exits 1 when none is alive or the router cannot be reached.",
    )
    parser.add_argument(
        "target", nargs="?", help="a profile (YAML file) or a namespace such as 'sim'"
    )
    parser.add_argument("--profile", type=Path, help="take the namespace and router from here")
    parser.add_argument(
        "--router",
        default=DEFAULT_ROUTER,
        help=f"router endpoint for a namespace target (default {DEFAULT_ROUTER})",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT_S, metavar="S")
    return parser


def target_of(args: argparse.Namespace) -> Target:
    """The target named by `--profile`, or by the positional profile or namespace."""
    if args.profile is not None:
        return Target.from_profile(args.profile)
    if args.target is None:
        raise QueryError("name a profile or a namespace, or pass --profile")
    if Path(args.target).is_file():
        return Target.from_profile(args.target)
    if Path(args.target).suffix:
        raise ProfileError(f"{args.target}: no such profile file (a namespace has no '.')")
    return Target.from_namespace(args.target, args.router)


def run(args: argparse.Namespace) -> int:
    """Print the live components and their status."""
    try:
        target = target_of(args)
        with target.open() as session:
            names = live_components(session, target.namespace, args.timeout)
            found = statuses(session, target.namespace, args.timeout) if names else {}
    except (ProfileError, QueryError, ValueError) as error:
        return fail(error)
    if args.json:
        rows = [
            {"name": name, "status": found[name].model_dump(mode="json") if name in found else None}
            for name in names
        ]
        emit(json_text(rows, indent=2))
    else:
        emit(format_table([(name, found.get(name)) for name in names]))
    if not names:
        print(f"no live component in namespace {target.namespace!r}", file=sys.stderr)
    return 0 if names else 1


def format_table(rows: list[tuple[str, ComponentStatus | None]]) -> str:
    """One line per component; a component that did not answer shows '?'."""
    cells = []
    for name, status in rows:
        if status is None:
            cells.append((name, "?", "?", "?", ""))
            continue
        counters = " ".join(f"{k}={v}" for k, v in sorted(status.counters.items()) if v)
        cells.append((name, status.module, status.state, str(status.pid), counters))
    return table(cells, COLUMNS, disable_numparse=True)
