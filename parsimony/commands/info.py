"""`parsimony info FILE`: what a recorded session holds (see record.session_reader.info); what
is stamped far outside the session (record.session_span) is said in one line on stderr."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from outputs.stdout import emit, json_text, table
from record.session_reader import info


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "info",
        help="channels, counts, rates, duration and schemas of a recording",
        description="Reads every complete chunk, so a file whose recorder was killed works too.",
    )
    parser.add_argument("file", type=Path, help="MCAP session")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    return parser


def run(args: argparse.Namespace) -> int:
    try:
        found = info(args.file)
    except OSError as error:
        print(f"info: {error}", file=sys.stderr)
        return 2
    if found["warning"] is not None:
        print(f"info: left out of the span and rates, {found['warning']}", file=sys.stderr)
    if args.json:
        emit(json_text(found, indent=2))
        return 0
    rows = [
        {
            "channel": c["key"],
            "schema": c["schema"],
            "schema_bytes": c["schema_bytes"],
            "messages": c["messages"],
            "rate_hz": c["rate_hz"],
        }
        for c in found["channels"]
    ]
    emit(
        f"{found['path']}: {found['messages']} messages, {found['bytes']} bytes, "
        f"{found['duration_s']} s from {found['start_ns']} to {found['end_ns']} ns"
    )
    if not found["complete"]:
        emit("no footer: cut short (parsimony record --recover FILE -o OUT makes it whole)")
    for damaged in found["damaged"]:
        emit(f"damaged, skipped: {damaged}")
    if found["dropped"]:
        lost = ", ".join(f"{n} ({counter})" for counter, n in found["dropped"].items())
        emit(f"lost by the recorder: {lost}")
    emit(table(rows))
    return 0
