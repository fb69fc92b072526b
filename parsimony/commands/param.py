"""`parsimony param get|set`: read or change a parameter of a running component."""

from __future__ import annotations

import argparse
import json
import os
import sys

from deploy.profile import ProfileError
from deploy.query import DEFAULT_TIMEOUT_S, QueryError, Target, get_param, set_param
from parsimony.output import emit

PROFILE_ENV = "PARSIMONY_PROFILE"
"""The profile used when `--profile` is not given."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `param get` and `param set`."""
    parser = subparsers.add_parser(
        "param",
        help="read or change a parameter of a running component",
        description="Read or change a declared parameter of a running component. "
        "Prints the value it has afterwards; exits 1 with the component's error otherwise.",
    )
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument(
        "--profile",
        default=os.environ.get(PROFILE_ENV),
        help=f"the deploy profile of the running system (default: ${PROFILE_ENV})",
    )
    common.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT_S, metavar="S")
    actions = parser.add_subparsers(dest="action", required=True)
    get = actions.add_parser("get", parents=[common], help="print a parameter's value")
    get.add_argument("component")
    get.add_argument("name")
    put = actions.add_parser("set", parents=[common], help="set it; print the new value")
    put.add_argument("component")
    put.add_argument("name")
    put.add_argument("value", help="the new value as text: 0.5, 3, true, pose")
    return parser


def run(args: argparse.Namespace) -> int:
    """Get or set the parameter and print `component.name = value`."""
    if args.profile is None:
        print(f"no profile: pass --profile or set {PROFILE_ENV}", file=sys.stderr)
        return 2
    try:
        target = Target.from_profile(args.profile)
        with target.open() as session:
            if args.action == "set":
                value = set_param(
                    session, target.namespace, args.component, args.name, args.value, args.timeout
                )
            else:
                value = get_param(
                    session, target.namespace, args.component, args.name, args.timeout
                )
    except (ProfileError, QueryError, ValueError) as error:
        print(error, file=sys.stderr)
        return 1
    emit(f"{args.component}.{args.name} = {json.dumps(value)}")
    return 0
