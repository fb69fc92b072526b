"""`parsimony status`: the live components of a namespace, a summary line each (messages in
and out, CPU time, the counters of faults that are not zero), and every counter on demand."""

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

COLUMNS = ("NAME", "MODULE", "STATE", "PID", "IN", "OUT", "CPU S", "FAULTS (non-zero)")
LEGEND = ("IN, OUT: messages received and published; FAULTS: counts of what was refused, "
          "failed, stalled, held or lost; --counters lists every counter")  # fmt: skip
FAULT_WORDS = ("rejected", "error", "overflowed", "fail", "bad_", "refus", "stall", "timeout",
               "lost", "non_finite", "implausible", "unreachable", "contacts", "penetrations",
               "undecodable", "out_of_limits", "fault", "degraded", "holds", "reconnects")
"""A counter whose name holds one of these counts faults; the summary shows it when not 0."""


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
    parser.add_argument("--json", action="store_true",
                        help="print JSON instead of a table (every counter)")  # fmt: skip
    parser.add_argument("-v", "--counters", action="store_true",
                        help="list every counter of each component under the table")  # fmt: skip
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
        rows = [(name, found.get(name)) for name in names]
        emit(format_table(rows) + (format_counters(rows) if args.counters else ""))
        if names and not args.counters:
            print(LEGEND, file=sys.stderr)
    if not names:
        print(f"no live component in namespace {target.namespace!r}", file=sys.stderr)
    return 0 if names else 1


def format_table(rows: list[tuple[str, ComponentStatus | None]]) -> str:
    """One line per component; a component that did not answer shows '?'."""
    cells = []
    for name, status in rows:
        if status is None:
            cells.append((name, "?", "?", "?", "?", "?", "?", ""))
            continue
        counters = status.counters
        faults = " ".join(f"{k}={v}" for k, v in sorted(counters.items())
                          if v and any(word in k for word in FAULT_WORDS))  # fmt: skip
        received = sum(v for k, v in counters.items() if k.startswith("received."))
        published = sum(v for k, v in counters.items() if k.startswith("published."))
        cpu_s = f"{counters.get('cpu_ms', 0) / 1e3:.1f}"
        cells.append((name, status.module, status.state, str(status.pid), str(received),
                      str(published), cpu_s, faults))  # fmt: skip
    return table(cells, COLUMNS, disable_numparse=True, colalign=("left",) * 4 + ("right",) * 3)


def format_counters(rows: list[tuple[str, ComponentStatus | None]]) -> str:
    """Every counter of each component that answered, one a line, under its name."""
    lines = []
    for name, status in rows:
        if status is not None:
            lines += ["", name]
            lines += [f"  {k:<40} {v}" for k, v in sorted(status.counters.items())]
    return "\n".join(lines)
