"""`parsimony param get|set|list|describe|dump|load`: the parameters of a running component."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import yaml

from launch.graph import component_class
from launch.query import QueryError, all_params, get_param, set_param, value_text
from outputs.stdout import emit, json_text
from parsimony.target_options import fail, profile_and_target, target_options
from profiles.access import DEFAULT_TOOL_USER, USER_ENV
from profiles.profile import ProfileError


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `param` and its actions."""
    parser = subparsers.add_parser(
        "param",
        help="read, change, describe, dump or load the parameters of a running component",
        description="Read or change the declared parameters of a running component. A value "
        "the component refuses exits 1 with its error, as does a set or load by a user "
        f"(${USER_ENV}, default {DEFAULT_TOOL_USER}) the profile's zenoh.access.parameters does "
        "not name for the component.",
    )
    common = target_options()
    actions = parser.add_subparsers(dest="action", required=True)
    get = actions.add_parser("get", parents=[common], help="print a parameter's value")
    get.add_argument("component")
    get.add_argument("name")
    put = actions.add_parser("set", parents=[common], help="set it; print the new value")
    put.add_argument("component")
    put.add_argument("name")
    put.add_argument("value", help="the new value as text: 0.5, 3, true, pose")
    listing = actions.add_parser("list", parents=[common], help="every parameter and its value")
    listing.add_argument("component")
    describe = actions.add_parser(
        "describe", parents=[common], help="type, default, bounds, choices and doc of each"
    )
    describe.add_argument("component")
    describe.add_argument("name", nargs="?")
    dump = actions.add_parser("dump", parents=[common], help="the values as YAML, to load back")
    dump.add_argument("component")
    load = actions.add_parser("load", parents=[common], help="set every value of a YAML file")
    load.add_argument("component")
    load.add_argument("file", type=Path)
    return parser


def describe(args: argparse.Namespace) -> list[dict]:
    """The declarations of the component's parameters, from its class."""
    profile, _ = profile_and_target(args)
    params = component_class(profile.component(args.component)).params
    rows = [
        {
            "name": p.name,
            "type": p.type.__name__,
            "default": p.default,
            "low": p.low,
            "high": p.high,
            "choices": list(p.choices) if p.choices else None,
            "doc": p.doc,
        }
        for p in params
        if args.name in (None, p.name)
    ]
    if not rows:
        raise QueryError(f"{args.component} declares no parameter {args.name!r}")
    return rows


def run(args: argparse.Namespace) -> int:
    """Carry out the action and print its result."""
    try:
        if args.action == "describe":
            rows = describe(args)
            emit(
                json_text(rows, indent=2)
                if args.json
                else "\n".join(
                    f"{r['name']}: {r['type']} = {r['default']!r}"
                    + (
                        f" in [{r['low']}, {r['high']}]"
                        if r["low"] is not None or r["high"] is not None
                        else ""
                    )
                    + (f" one of {r['choices']}" if r["choices"] else "")
                    + f"  {r['doc']}"
                    for r in rows
                )
            )
            return 0
        profile, target = profile_and_target(args)
        access = profile.zenoh.access
        why = (
            access.why_not_set(args.component, None)
            if access is not None and args.action in ("set", "load")
            else ""
        )
        if why:
            raise QueryError(f"param {args.action} refused: {why}; ${USER_ENV} names the user")
        with target.open() as session:
            ns, component = target.namespace, args.component
            if args.action == "get":
                values = {args.name: get_param(session, ns, component, args.name, args.timeout)}
            elif args.action == "set":
                values = {
                    args.name: set_param(
                        session, ns, component, args.name, args.value, args.timeout
                    )
                }
            elif args.action == "load":
                wanted = yaml.safe_load(args.file.read_text())
                if not isinstance(wanted, dict):
                    raise QueryError(f"{args.file}: expected a mapping of parameter: value")
                values = {
                    name: set_param(session, ns, component, name, value_text(value), args.timeout)
                    for name, value in wanted.items()
                }
            else:
                values = all_params(session, ns, component, args.timeout)
    except (ProfileError, QueryError, KeyError, LookupError, OSError, ValueError) as error:
        return fail(error)
    if args.json:
        emit(json_text(values, indent=2))
    elif args.action == "dump":
        emit(yaml.safe_dump(values, sort_keys=False).rstrip())
    else:
        emit("\n".join(f"{args.component}.{name} = {json.dumps(v)}" for name, v in values.items()))
    return 0
