"""JSON Schema of every message type, and an index of the topics they travel on.

``export_schemas(directory)`` writes ``<TypeName>.json`` for each type of
``MESSAGE_TYPES`` (nested models are in its ``$defs``) and ``index.json``::

    {"format_tag": "parsimony/1", "format_version": 1,
     "topics": {"robot/state": "RobotState", ...},
     "keys": {"component/*/status": "ComponentStatus"},
     "types": {"RobotState": "RobotState.json", ...}}

``topics`` maps each topic suffix to its type; ``keys`` does the same for the
per-component keys of the topic table (``*`` stands for the component name).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from messages.codec import FORMAT_TAG, FORMAT_VERSION
from messages.topics import MESSAGE_TYPES, STATUS_TYPE, TOPICS

INDEX_FILE = "index.json"


def json_schema(message_type: type[BaseModel]) -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of one message type."""
    return message_type.model_json_schema()


def schema_index() -> dict[str, Any]:
    """The wire format, each topic suffix's type, and each type's schema file."""
    return {
        "format_tag": FORMAT_TAG,
        "format_version": FORMAT_VERSION,
        "topics": {topic.suffix: topic.type.__name__ for topic in TOPICS.values()},
        "keys": {"component/*/status": STATUS_TYPE.__name__},
        "types": {t.__name__: _schema_file(t) for t in MESSAGE_TYPES},
    }


def export_schemas(directory: str | Path) -> list[Path]:
    """Write one schema per message type and the index into ``directory``
    (created if missing); return the paths written, the index last."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = [
        _write_json(directory / _schema_file(message_type), json_schema(message_type))
        for message_type in MESSAGE_TYPES
    ]
    written.append(_write_json(directory / INDEX_FILE, schema_index()))
    return written


def _schema_file(message_type: type[BaseModel]) -> str:
    return f"{message_type.__name__}.json"


def _write_json(path: Path, document: dict[str, Any]) -> Path:
    path.write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    return path
