"""`parsimony schema`: print the message index, or export every JSON Schema."""

from __future__ import annotations

import argparse
from pathlib import Path

from messages.schema import export_schemas, schema_index
from outputs.stdout import emit, json_text


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "schema",
        help="print the topic/type index, or write the JSON Schema of every message",
        description=__doc__,
    )
    parser.add_argument(
        "--out",
        type=Path,
        metavar="DIR",
        help="write <TypeName>.json per message type and index.json into DIR",
    )
    return parser


def run(args: argparse.Namespace) -> int:
    if args.out is None:
        emit(json_text(schema_index(), indent=2))
        return 0
    for path in export_schemas(args.out):
        emit(str(path))
    return 0
