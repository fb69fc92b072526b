"""Sessions as MCAP files: one channel per key expression, each message with its schema.

The project's messages are written as JSON (schema encoding ``jsonschema``, the type's JSON
Schema; ``bytes`` fields base64), so Foxglove plots them as they are, and read back into their
pydantic types exactly (Python's JSON floats round-trip bit for bit). Other channels (the
Foxglove views) are written raw. Chunks are zstd-compressed; ``flush`` closes the current one,
so a writer killed by SIGKILL loses at most what came since. A file without a footer reads
back by its complete chunks (``read_session``, ``info``) and ``recover`` makes it whole.
"""

from __future__ import annotations

import base64
import functools
import json
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader
from mcap.writer import CompressionType, Writer
from pydantic import BaseModel

from messages import topics
from messages.schema import json_schema

PROJECT_ENCODING = "json"
"""The message encoding of the project's own channels."""


@dataclass(frozen=True)
class Recorded:
    """One message read back: its key, its topic's name (None for another channel), its log
    time and the decoded message (None for a channel that is not the project's)."""

    key: str
    topic_name: str | None
    log_time_ns: int
    message: BaseModel | None


def stamp_of(message: BaseModel) -> int:
    """A message's stamp: its header's (a Clock has only ``stamp_ns``)."""
    header = getattr(message, "header", None)
    return header.stamp_ns if header is not None else message.stamp_ns


def to_json(message: BaseModel) -> bytes:
    """The message as JSON, ``bytes`` fields as base64 strings."""
    return json.dumps(message.model_dump(mode="python"), default=_bytes_as_text).encode()


def _bytes_as_text(value: object) -> str:
    if isinstance(value, bytes):
        return base64.b64encode(value).decode()
    raise TypeError(f"cannot write {type(value).__name__} as JSON")


def from_json(data: bytes, message_type: type[BaseModel]) -> BaseModel:
    """The message of ``to_json``, exactly: base64 strings back into its ``bytes`` fields."""
    fields = json.loads(data)
    for name, field in message_type.model_fields.items():
        if field.annotation is bytes and isinstance(fields.get(name), str):
            fields[name] = base64.b64decode(fields[name])
    return message_type.model_validate(fields)


@functools.cache
def schema_bytes(message_type: type[BaseModel]) -> bytes:
    """The JSON Schema of a message type, once per type (pydantic takes a millisecond)."""
    return json.dumps(json_schema(message_type)).encode()


class SessionWriter:
    """An MCAP file being written (a context manager; ``close`` writes the footer)."""

    def __init__(self, path: Path, chunk_size: int = 1024 * 1024) -> None:
        self._file: IO[bytes] = Path(path).open("wb")
        self._writer = Writer(self._file, chunk_size=chunk_size,
                              compression=CompressionType.ZSTD)  # fmt: skip
        self._writer.start(profile="", library="parsimony")
        self._schemas: dict[tuple[str, str], int] = {}
        self._channels: dict[str, int] = {}
        self._sequence = 0
        self._closed = False

    def __enter__(self) -> SessionWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def write(self, key: str, message: BaseModel, log_time_ns: int | None = None) -> None:
        """``message`` on the channel of ``key``, logged at its stamp unless given."""
        message_type = type(message)
        schema = schema_bytes(message_type)
        self.write_raw(key, message_type.__name__, "jsonschema", schema, PROJECT_ENCODING,
                       to_json(message), stamp_of(message) if log_time_ns is None
                       else log_time_ns)  # fmt: skip

    def write_raw(self, key: str, schema_name: str, schema_encoding: str, schema_data: bytes,
                  message_encoding: str, data: bytes, log_time_ns: int) -> None:  # fmt: skip
        """Any message on the channel ``key`` (created with its schema on first use)."""
        channel = self._channels.get(key)
        if channel is None:
            schema = self._schemas.get((schema_name, schema_encoding))
            if schema is None:
                schema = self._writer.register_schema(schema_name, schema_encoding, schema_data)
                self._schemas[(schema_name, schema_encoding)] = schema
            channel = self._writer.register_channel(key, message_encoding, schema)
            self._channels[key] = channel
        self._sequence += 1
        self._writer.add_message(channel, log_time_ns, data, time.time_ns(), self._sequence)

    def flush(self) -> None:
        """Close the current chunk and push it to the file: a kill loses nothing before."""
        if not self._closed:
            self._writer.flush()

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._writer.finish()
            self._file.close()


def _records(path: Path) -> Iterator[tuple[Any, Any, Any]]:
    """(schema, channel, message) of every complete chunk, in file order; stops quietly where a
    file without a footer ends."""
    with Path(path).open("rb") as stream:
        reader = NonSeekingReader(stream)
        try:
            yield from reader.iter_messages(log_time_order=False)
        except (McapError, EOFError, ValueError, AssertionError):  # the cut at the end
            return


def read_session(path: Path) -> Iterator[Recorded]:
    """Every message of a session file, its project's messages decoded, in log-time order."""
    by_suffix = {topic.suffix: topic for topic in topics.TOPICS.values()}
    found = []
    for schema, channel, message in _records(path):
        topic = None
        if channel.message_encoding == PROJECT_ENCODING and schema is not None:
            topic = next((t for suffix, t in by_suffix.items() if channel.topic.endswith(
                "/" + suffix) and t.type.__name__ == schema.name), None)  # fmt: skip
        decoded = from_json(message.data, topic.type) if topic is not None else None
        name = topic.name if topic is not None else None
        found.append(Recorded(channel.topic, name, message.log_time, decoded))
    found.sort(key=lambda r: r.log_time_ns)
    yield from found


def info(path: Path) -> dict[str, Any]:
    """Channels (key, schema name and size, count, first and last log time, rate) and totals."""
    channels: dict[str, dict[str, Any]] = {}
    for schema, channel, message in _records(path):
        entry = channels.setdefault(channel.topic, {
            "key": channel.topic, "schema": schema.name if schema else "",
            "schema_bytes": len(schema.data) if schema else 0,
            "encoding": channel.message_encoding, "messages": 0, "bytes": 0,
            "start_ns": message.log_time, "end_ns": message.log_time,
        })  # fmt: skip
        entry["messages"] += 1
        entry["bytes"] += len(message.data)
        entry["start_ns"] = min(entry["start_ns"], message.log_time)
        entry["end_ns"] = max(entry["end_ns"], message.log_time)
    for entry in channels.values():
        span = (entry["end_ns"] - entry["start_ns"]) / 1e9
        entry["rate_hz"] = round((entry["messages"] - 1) / span, 2) if span > 0 else 0.0
    start = min((c["start_ns"] for c in channels.values()), default=0)
    end = max((c["end_ns"] for c in channels.values()), default=0)
    return {
        "path": str(path),
        "messages": sum(c["messages"] for c in channels.values()),
        "bytes": Path(path).stat().st_size,
        "start_ns": start,
        "end_ns": end,
        "duration_s": round((end - start) / 1e9, 3),
        "channels": sorted(channels.values(), key=lambda c: c["key"]),
    }


def recover(source: Path, target: Path) -> int:
    """A whole file (footer, index) at ``target`` of what survives in ``source``; the number of
    messages saved."""
    saved = 0
    with SessionWriter(target) as writer:
        for schema, channel, message in _records(source):
            writer.write_raw(channel.topic, schema.name if schema else "",
                             schema.encoding if schema else "", schema.data if schema else b"",
                             channel.message_encoding, message.data, message.log_time)  # fmt: skip
            saved += 1
    return saved
