"""`parsimony status`: the live components of a namespace, a summary line each (messages in
and out, CPU time, the counters of faults that are not zero), and every counter on demand;
with ``--wait``, once every component of a profile is alive."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from launch.alive import wait_alive
from launch.query import (
    DEFAULT_ROUTER,
    DEFAULT_TIMEOUT_S,
    QueryError,
    Target,
    live_components,
    statuses,
)
from messages.status import ComponentStatus
from outputs.stdout import emit, json_text, table
from parsimony.argument_types import positive_seconds
from parsimony.target_options import fail
from profiles.profile import ProfileError, load_profile

COLUMNS = ("NAME", "MODULE", "STATE", "PID", "IN", "OUT", "CPU S", "FAULTS (non-zero)")
LEGEND = (
    "IN, OUT: messages received and published; FAULTS: counts of what was refused, "
    "failed, stalled, held or lost; --counters lists every counter"
)
FAULT_WORDS = (
    "rejected",
    "error",
    "overflowed",
    "missed",
    "fail",
    "bad_",
    "refus",
    "stall",
    "timeout",
    "lost",
    "non_finite",
    "implausible",
    "unreachable",
    "contacts",
    "penetrations",
    "undecodable",
    "out_of_limits",
    "fault",
    "degraded",
    "holds",
    "reconnects",
)
"""A counter whose name holds one of these counts faults; the summary shows it when not 0."""
WAIT_TIMEOUT_S = 60.0
"""How long ``--wait`` waits for every component by default."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `status` and its arguments."""
    parser = subparsers.add_parser(
        "status",
        help="list the live components of a namespace",
        description="List the components whose liveliness token is present, with their "
        "state and counters. With --wait, first wait until every enabled component of the "
        "profile is alive (and its router reachable), saying on stderr which are missing. "
        "Exits 1 when none is alive, or with --wait when some are not in time; 2 when the "
        "router cannot be reached.",
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
    parser.add_argument(
        "--json", action="store_true", help="print JSON instead of a table (every counter)"
    )
    parser.add_argument(
        "-v",
        "--counters",
        action="store_true",
        help="list every counter of each component under the table",
    )
    parser.add_argument(
        "--wait", action="store_true", help="wait until every component of the profile is alive"
    )
    parser.add_argument(
        "--timeout",
        type=positive_seconds,
        metavar="S",
        help="seconds to wait for the components' answers (default "
        f"{DEFAULT_TIMEOUT_S:g}); with --wait, for all of them to be alive "
        f"(default {WAIT_TIMEOUT_S:g})",
    )
    return parser


def profile_of(args: argparse.Namespace) -> Path | None:
    """The profile named by `--profile` or the positional target, if any."""
    if args.profile is not None:
        return args.profile
    if args.target is not None and Path(args.target).is_file():
        return Path(args.target)
    return None


def target_of(args: argparse.Namespace) -> Target:
    """The target named by `--profile`, or by the positional profile or namespace."""
    profile = profile_of(args)
    if profile is not None:
        return Target.from_profile(profile)
    if args.target is None:
        raise QueryError("name a profile or a namespace, or pass --profile")
    if Path(args.target).suffix:
        raise ProfileError(f"{args.target}: no such profile file (a namespace has no '.')")
    return Target.from_namespace(args.target, args.router)


def wait(args: argparse.Namespace, target: Target) -> None:
    """Wait until every enabled component of the profile is alive (``--wait``)."""
    profile = profile_of(args)
    if profile is None:
        raise ProfileError("--wait waits for the components of a profile: name one")
    names = [spec.name for spec in load_profile(profile).start_order()]
    timeout_s = WAIT_TIMEOUT_S if args.timeout is None else args.timeout
    wait_alive(
        target, names, timeout_s, lambda text: print(f"status: {text}", file=sys.stderr, flush=True)
    )


def run(args: argparse.Namespace) -> int:
    """Print the live components and their status."""
    timeout_s = DEFAULT_TIMEOUT_S if args.timeout is None or args.wait else args.timeout
    try:
        target = target_of(args)
        if args.wait:
            wait(args, target)
        with target.open() as session:
            names = live_components(session, target.namespace, timeout_s)
            found = statuses(session, target.namespace, timeout_s) if names else {}
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
        faults = " ".join(
            f"{k}={v}"
            for k, v in sorted(counters.items())
            if v and any(word in k for word in FAULT_WORDS)
        )
        received = sum(v for k, v in counters.items() if k.startswith("received."))
        published = sum(v for k, v in counters.items() if k.startswith("published."))
        cpu_s = f"{counters.get('cpu_ms', 0) / 1e3:.1f}"
        cells.append(
            (
                name,
                status.module,
                status.state,
                str(status.pid),
                str(received),
                str(published),
                cpu_s,
                faults,
            )
        )
    return table(cells, COLUMNS, disable_numparse=True, colalign=("left",) * 4 + ("right",) * 3)


def format_counters(rows: list[tuple[str, ComponentStatus | None]]) -> str:
    """Every counter of each component that answered, one a line, under its name."""
    lines = []
    for name, status in rows:
        if status is not None:
            lines += ["", name]
            lines += [f"  {k:<40} {v}" for k, v in sorted(status.counters.items())]
    return "\n".join(lines)
