"""`parsimony record PROFILE -o FILE`: every message of a running system into an MCAP file,
until Ctrl-C (the recorder component of components.recorder, run in the foreground); or
`--recover FILE -o OUT`: a whole file from what survives of one whose recorder was killed."""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

from parsimony.experiment import RECORDER_STOP_S
from parsimony.output import emit
from profiles.profile import ProfileError, load_profile
from record.session_file import recover


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser("record", help="record a running system to MCAP",
                                   description=__doc__)  # fmt: skip
    parser.add_argument("profile", type=Path, nargs="?", help="deploy profile of the system")
    parser.add_argument("-o", "--output", type=Path, required=True, help="the MCAP file")
    parser.add_argument("--keys", nargs="*", default=["*"], help="topic name patterns")
    parser.add_argument("--recover", type=Path, metavar="FILE", help="a killed recording")
    return parser


def run(args: argparse.Namespace) -> int:
    if args.recover is not None:
        try:
            saved = recover(args.recover, args.output)
        except OSError as error:
            print(f"record: {error}", file=sys.stderr)
            return 2
        emit(f"{saved} messages saved to {args.output}")
        return 0
    if args.profile is None:
        print("record: a profile, or --recover FILE", file=sys.stderr)
        return 2
    try:
        load_profile(args.profile)
    except ProfileError as error:
        print(error, file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory() as directory:
        profile = Path(directory) / "record.yaml"
        params = {"path": str(args.output.resolve()), "keys": ",".join(args.keys)}
        profile.write_text(yaml.safe_dump({
            "extends": str(args.profile.resolve()),
            "components": [{"name": "recorder", "module": "recorder", "role": "recorder",
                            "stop_timeout_s": RECORDER_STOP_S, "params": params,
                            "restart": {"policy": "never"}}],
        }))  # fmt: skip
        command = [sys.executable, "-m", "components.recorder", "--profile", str(profile),
                   "--name", "recorder"]  # fmt: skip
        process = subprocess.Popen(command)
        try:
            return process.wait()
        except KeyboardInterrupt:
            return process.wait()
