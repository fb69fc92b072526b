"""`parsimony node info COMPONENT`: what a running component reads and writes, its state."""

from __future__ import annotations

import argparse
import json

from launch.graph import component_class
from launch.query import QueryError, status_of
from outputs.stdout import emit, json_text
from parsimony.target_options import fail, profile_and_target, target_options
from profiles.profile import ProfileError


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `node info`."""
    parser = subparsers.add_parser("node", help="describe a running component")
    actions = parser.add_subparsers(dest="action", required=True)
    info = actions.add_parser(
        "info",
        parents=[target_options()],
        help="its module, role, state, topics, counters, parameters",
    )
    info.add_argument("component")
    return parser


def run(args: argparse.Namespace) -> int:
    try:
        profile, target = profile_and_target(args)
        spec = profile.component(args.component)
        cls = component_class(spec)
        with target.open() as session:
            status = status_of(session, target.namespace, args.component, args.timeout)
    except (ProfileError, QueryError, KeyError, LookupError) as error:
        return fail(error)
    info = {
        "name": spec.name,
        "module": spec.module_path,
        "role": spec.role,
        "state": status.state,
        "pid": status.pid,
        "reads": [i.describe() for i in cls.reads],
        "writes": [t.name for t in cls.writes],
        "counters": status.counters,
        "parameters": status.parameters,
    }
    if args.json:
        emit(json_text(info, indent=2))
        return 0
    lines = [
        f"{info['name']} ({info['module']}, {info['role']}): {info['state']}, pid {info['pid']}",
        f"  reads  {', '.join(info['reads']) or '-'}",
        f"  writes {', '.join(info['writes']) or '-'}",
        "  counters",
    ]
    lines += [f"    {name} = {value}" for name, value in sorted(status.counters.items())]
    lines.append("  parameters")
    lines += [f"    {name} = {json.dumps(value)}" for name, value in status.parameters.items()]
    emit("\n".join(lines))
    return 0
