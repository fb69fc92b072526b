"""`parsimony experiment`: a chapter 6 experiment on the whole simulated loop (see
studies.experiment)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import get_args

import yaml

from launch.query import QueryError
from outputs.stdout import emit, json_text
from parsimony.commands.robot_option import add_robot_option
from profiles.profile import Profile, ProfileError
from sim2d.scenarios import NAMES, SEED_MAX
from studies.experiment import PROFILES, TIME_LIMIT_S, Options, run_experiment
from wbc.robot import RobotDescriptionError

EXIT_NOT_CONVERGED = 1
EXIT_USAGE = 2


def seconds_window(text: str) -> tuple[float, float]:
    """``FROM,TO`` in simulated seconds, FROM < TO."""
    try:
        start, end = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected FROM,TO in seconds, got {text!r}") from None
    if not 0.0 <= start < end:
        raise argparse.ArgumentTypeError(f"expected 0 <= FROM < TO, got {text!r}")
    return start, end


def seed(text: str) -> int:
    """A seed, 0 to ``SEED_MAX``."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
    if not 0 <= value <= SEED_MAX:
        raise argparse.ArgumentTypeError(f"expected 0 to {SEED_MAX}, got {value}")
    return value


def time_limit(text: str) -> float:
    """A finite, positive number of simulated seconds."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds, got {text!r}") from None
    if not (value > 0.0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"expected a finite number of seconds > 0, got {text}")
    return value


def gain_setting(text: str) -> tuple[str, object]:
    """``NAME=VALUE``, the value read as a YAML scalar (``0.2``, ``border``, ``true``)."""
    name, equals, value = text.partition("=")
    if not (equals and name and value):
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {text!r}")
    try:
        return name, yaml.safe_load(value)
    except yaml.YAMLError:
        raise argparse.ArgumentTypeError(f"{name}: cannot read the value {value!r}") from None


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "experiment",
        help="run a chapter 6 experiment on the simulated loop and write its report",
        description="Launch the simulation profile headless with the experiment's set-up, "
        "run until the goal is reached or the time limit passes, write OUT/report.json. "
        "Exits 0 when it converged, 1 when not, 2 on a usage or configuration error.",
    )
    parser.add_argument("name", choices=NAMES, help="the experiment of section 6.2")
    parser.add_argument("--controller", choices=tuple(PROFILES), default="lp")
    parser.add_argument("--out", type=Path, required=True, help="directory of the report")
    parser.add_argument("--force", action="store_true", help="replace what --out holds")
    parser.add_argument("--seed", type=seed, help="draw the start and the bin from the ranges")
    parser.add_argument("--profile", type=Path, help="simulation profile to extend")
    add_robot_option(
        parser,
        "run another robot: a zoo name (deploy/robots/NAME.yaml) or a description's file, in "
        "place of the profile's; its goal is derived from it",
        default=None,
    )
    parser.add_argument(
        "--realtime",
        action="store_true",
        help="run at the wall clock's pace instead of in lockstep",
    )
    parser.add_argument(
        "--time-limit",
        type=time_limit,
        default=TIME_LIMIT_S,
        metavar="S",
        help="simulated seconds before giving up",
    )
    parser.add_argument(
        "--hide-base-marker",
        type=seconds_window,
        metavar="FROM,TO",
        help="hide the base marker from the camera then (sim s)",
    )
    parser.add_argument(
        "--gain",
        type=gain_setting,
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a gain of the controller's law in place "
        "of the experiment's (repeatable; the LP's and the QP's: LPParams, the "
        "cascade's: CascadeParams), e.g. obstacle_mode=border, or saturate=true "
        "with --controller cascade",
    )
    parser.add_argument(
        "--processes",
        choices=get_args(Profile.model_fields["processes"].annotation),
        help="the components in a process each, or sharing one (by default shared in lockstep, "
        "the profile's own otherwise)",
    )
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    return parser


def run(args: argparse.Namespace) -> int:
    holds = args.out.exists() and not (args.out.is_dir() and not any(args.out.iterdir()))
    if holds and not args.force:
        print(
            f"experiment: {args.out} is not empty; give --force to write over what it holds",
            file=sys.stderr,
        )
        return EXIT_USAGE
    options = Options(
        name=args.name,
        controller=args.controller,
        out=args.out,
        seed=args.seed,
        profile=args.profile,
        realtime=args.realtime,
        time_limit_s=args.time_limit,
        hide_base_marker=args.hide_base_marker,
        robot=args.robot,
        gains=dict(args.gain),
        processes=args.processes,
    )
    try:
        report = run_experiment(options)
    except (ProfileError, RobotDescriptionError, OSError, QueryError, RuntimeError) as error:
        print(f"experiment: {error}", file=sys.stderr)
        return EXIT_USAGE
    if args.json:
        emit(json_text(report, indent=2))
    else:
        keys = (
            "converged",
            "final_error",
            "sim_time_s",
            "wall_time_s",
            "real_time_factor",
            "contacts",
            "arm_penetrations",
        )
        summary = {k: report[k] for k in keys}
        summary["recording"] = "whole" if report["recording"]["whole"] else "CUT_SHORT"
        emit(" ".join(f"{k}={v}" for k, v in summary.items()))
    for missing in report["recording"]["missing"]:
        print(
            f"[experiment] WARNING: the recording is cut short: {missing}; the figures show "
            "only what it holds",
            file=sys.stderr,
        )
    print(f"[experiment] report: {args.out / 'report.json'}", file=sys.stderr)
    print(f"[experiment] figures: {', '.join(report.get('figures', []))}", file=sys.stderr)
    print(
        f"[experiment] recording: {args.out / 'session.mcap'} (parsimony info, replay, "
        "report; Foxglove opens it)",
        file=sys.stderr,
    )
    return 0 if report["converged"] else EXIT_NOT_CONVERGED
