"""`parsimony doctor PROFILE`: the checklist of a profile's hardware (``launch.doctor``), each
line ok, a warning or a fault with its fix; exit 1 when a fault would stop the profile."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from launch.doctor import checklist
from launch.doctor_devices import Check
from outputs.stdout import emit, json_text
from profiles.profile import ProfileError, load_profile

MARKS = {"ok": "ok  ", "warn": "WARN", "fail": "FAIL"}


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `doctor` and its arguments."""
    parser = subparsers.add_parser(
        "doctor",
        help="check a profile's hardware before it runs (ports, servos, Create, camera, clocks)",
        description="Checks the serial ports, the arm's servos (id, baud rate, model, angle "
        "limits, torque), the Create (OI mode, battery), the camera (its calibration's image "
        "size, the reference marker in view) and the clocks. Only reads: nothing moves. Exit "
        "1 when a fault would stop the profile from running.",
    )
    parser.add_argument("profile", type=Path, help="deploy profile (YAML)")
    parser.add_argument("--json", action="store_true", help="print the checklist as JSON")
    return parser


def _line(check: Check) -> str:
    text = f"{MARKS[check.status]}  {check.name}: {check.detail}"
    return f"{text}\n      fix: {check.fix}" if check.fix else text


def run(args: argparse.Namespace) -> int:
    try:
        profile = load_profile(args.profile)
    except ProfileError as error:
        print(error, file=sys.stderr)
        return 2
    started = time.monotonic()
    say = (lambda check: None) if args.json else (lambda check: emit(_line(check)))
    lines = checklist(profile, say)
    faults = sum(check.status == "fail" for check in lines)
    if args.json:
        seconds = round(time.monotonic() - started, 3)
        report = {"profile": str(args.profile), "ok": not faults, "seconds": seconds}
        emit(json_text({**report, "checks": [check.json() for check in lines]}, indent=2))
    else:
        warnings = sum(check.status == "warn" for check in lines)
        emit(f"{len(lines)} checks: {faults} faults, {warnings} warnings")
    return 1 if faults else 0
