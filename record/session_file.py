"""Sessions as MCAP files: one channel per key expression, every channel with its schema.

The project's messages go in as JSON (message encoding ``json``, schema encoding ``jsonschema``,
schema name the type's name, schema data its JSON Schema, ``bytes`` fields as base64 strings
marked ``"contentEncoding": "base64"``), so Foxglove plots them as they are, and come back into
their pydantic types exactly: a float is written as its shortest round-trip text, which reads
back bit for bit. Beside a message go its Foxglove views (``scenes.foxglove_views``), when asked
for, on channels of their own. Each image is stored once: a view that carries a field as it is
(a frame's JPEG or pixels in its ``foxglove.CompressedImage`` or ``RawImage``) holds it, and the
message's JSON leaves it out; the channel's metadata names the carrier (``CARRIED_FIELD``,
``CARRIER``), and reading puts the field back from the view of the same log time. Other channels
are written as given (``write_raw``). Chunks are zstd-compressed; ``flush`` closes the current
one and pushes it to the file, so a writer killed by SIGKILL loses only what came after its last
flush.

Reading them back is ``record.session_reader``'s.
"""

from __future__ import annotations

import base64
import functools
import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from mcap.writer import CompressionType, Writer
from pydantic import BaseModel

from messages import topics
from messages.schema import json_schema
from scenes.foxglove_views import PLAIN, Viewer, everything, view_channel

MESSAGE_ENCODING = "json"
"""The message encoding of the project's own channels."""
SCHEMA_ENCODING = "jsonschema"
"""The schema encoding of the project's own channels."""
LIBRARY = "parsimony"
"""What the MCAP header names as the writer."""
SEQUENCE_MODULUS = 2**32
"""MCAP's message sequence is a uint32 per channel; it wraps."""
CARRIED_FIELD = "parsimony.carried_field"
"""Channel metadata: the field the channel's JSON leaves out, because ``CARRIER`` holds it."""
CARRIER = "parsimony.carrier"
"""Channel metadata: the channel whose message of the same log time holds ``CARRIED_FIELD``."""
DROPPED = "parsimony.dropped"
"""Metadata record: the samples the recorder lost, by counter (``overflowed.<topic>``,
``overwritten.<topic>``, and ``missed.<topic>``: those that never reached it), those that are not
0; written as they change and at the end."""


@dataclass(frozen=True)
class Recorded:
    """One message read back: the channel's key, its topic's name in ``topics.TOPICS`` and the
    decoded message, or ``None`` and ``None`` for a channel that is not one of the project's
    (a Foxglove view), and the log time in ns."""

    key: str
    topic_name: str | None
    log_time_ns: int
    message: BaseModel | None


def stamp_of(message: BaseModel) -> int:
    """A message's stamp in ns: its header's (a ``Clock`` has only ``stamp_ns``)."""
    header = getattr(message, "header", None)
    return header.stamp_ns if header is not None else message.stamp_ns


@functools.cache
def bytes_fields(message_type: type[BaseModel]) -> tuple[str, ...]:
    """The top-level ``bytes`` fields of a type: written as base64 strings."""
    return tuple(n for n, f in message_type.model_fields.items() if f.annotation is bytes)


def to_json(message: BaseModel, left_out: str = "") -> bytes:
    """``message`` as compact JSON, its ``bytes`` fields base64 (nested bytes are refused), the
    field ``left_out`` (one a view carries) left out.

    Without a bytes field to write (the recorder's: an image's JSON leaves its pixels to the
    view that carries them), the model's own compiled serializer writes it, in a fifth of the
    time of ``json.dumps``: the same fields and values (a float's exponent is written ``1e-5``,
    not ``1e-05``; text is UTF-8, not escaped). A bytes field (an image) is neither copied by
    ``model_dump`` nor scanned by ``json.dumps``: a marker holds its place, then gives it to
    the base64 text, which needs no escaping.
    """
    if _bytes_free(type(message), left_out):  # no bytes field either; every float finite
        exclude = {left_out} if left_out else None
        return type(message).__pydantic_serializer__.to_json(message, exclude=exclude)
    names = [name for name in bytes_fields(type(message)) if name != left_out]
    dumped = message.model_dump(exclude={*bytes_fields(type(message)), left_out})
    fields = {
        name: BYTES_MARKER if name in names else dumped[name]
        for name in type(message).model_fields
        if name != left_out
    }
    text = json.dumps(fields, allow_nan=False, separators=(",", ":")).encode()
    for name in names:
        value = b'"' + base64.b64encode(getattr(message, name)) + b'"'
        text = text.replace(_ENCODED_MARKER, value, 1)
    return text


@functools.cache
def _bytes_free(message_type: type[BaseModel], left_out: str) -> bool:
    """Whether the JSON of a type, ``left_out`` left out, holds no bytes at any depth (its
    schema no ``binary`` string): one that does goes the way that refuses nested bytes."""
    return b'"binary"' not in schema_of(message_type, left_out)


BYTES_MARKER = "\u0000bytes\u0000"
"""Holds a bytes field's place in ``to_json`` (a NUL-delimited string no field carries)."""
_ENCODED_MARKER = json.dumps(BYTES_MARKER).encode()


@dataclass(frozen=True)
class Entry:
    """One record of a message as a session holds it: its channel (key, schema, encoding and
    metadata) and its data."""

    channel: str
    schema_name: str
    schema_encoding: str
    schema_data: bytes
    message_encoding: str
    data: bytes
    metadata: tuple[tuple[str, str], ...] = ()


def entries(
    key: str,
    message: BaseModel,
    views: bool = True,
    viewer: Viewer = PLAIN,
    wanted: Callable[[str], bool] = everything,
) -> list[Entry]:
    """A project message on ``key`` as a session (or a live view) holds it: its JSON on the
    channel ``key``, then, if ``views``, each Foxglove view (of ``viewer``) on its own channel;
    a field that a view carries is left out of the JSON, which names the carrier in its
    metadata. Only the channels ``wanted`` (by name) are made: a live view leaves out those no
    client reads."""
    topic = topic_of(key, type(message).__name__) if views else None
    found = (
        viewer(topic.name, key, message, lambda suffix: wanted(view_channel(key, suffix)))
        if topic is not None
        else []
    )
    carrier = viewer.carrier(topic.name) if topic is not None else None
    made: list[Entry] = []
    if wanted(key):
        left_out, metadata = "", ()
        if carrier is not None:
            left_out, suffix = carrier
            metadata = ((CARRIED_FIELD, left_out), (CARRIER, view_channel(key, suffix)))
        made.append(
            Entry(
                key,
                type(message).__name__,
                SCHEMA_ENCODING,
                schema_of(type(message), left_out),
                MESSAGE_ENCODING,
                to_json(message, left_out),
                metadata,
            )
        )
    return [*made, *(Entry(*v.channel(key)) for v in found)]


def from_json(
    data: bytes, message_type: type[BaseModel], carried_fields: dict[str, bytes] | None = None
) -> BaseModel:
    """The message ``to_json`` wrote, exactly (``model_validate`` of the decoded JSON), with
    the fields it left out taken from ``carried_fields``. A type without bytes fields, none
    carried, is parsed and validated by its model's own JSON validator in one step (half the
    time: reading a run's recording back is most of its judgement)."""
    if not carried_fields and not bytes_fields(message_type):
        return message_type.model_validate_json(data)
    fields = json.loads(data)
    for name in bytes_fields(message_type):
        if isinstance(fields.get(name), str):
            fields[name] = base64.b64decode(fields[name], validate=True)
    return message_type.model_validate({**fields, **(carried_fields or {})})


@functools.cache
def schema_of(message_type: type[BaseModel], left_out: str = "") -> bytes:
    """The JSON Schema of a type as written in the file, base64 fields marked as such, the
    field ``left_out`` (carried by a view) left out."""
    schema = json_schema(message_type)
    properties = {n: p for n, p in schema["properties"].items() if n != left_out}
    for name in bytes_fields(message_type):
        if name != left_out:
            properties[name] = {**properties[name], "contentEncoding": "base64"}
    required = [n for n in schema.get("required", ()) if n != left_out]
    return json.dumps({**schema, "properties": properties, "required": required}).encode()


class SessionWriter:
    """An MCAP file being written: a context manager, ``close`` writes the footer.

    ``chunk_size`` is the uncompressed size (bytes) at which a chunk is closed on its own;
    ``viewer`` makes the Foxglove views (``scenes.foxglove_views.Viewer``: give it the robot
    description, and the file draws the robot).
    """

    def __init__(
        self, path: Path, chunk_size: int = 1024 * 1024, viewer: Viewer | None = None
    ) -> None:
        self._viewer = viewer if viewer is not None else Viewer()
        self._file = Path(path).open("wb")
        self._writer = Writer(self._file, chunk_size=chunk_size, compression=CompressionType.ZSTD)
        self._writer.start(library=LIBRARY)
        self._schemas: dict[tuple[str, str, bytes], int] = {}
        self._channels: dict[tuple[str, tuple[str, str, bytes]], int] = {}
        self._sequences: dict[int, int] = {}
        self._closed = False

    def __enter__(self) -> SessionWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def write(
        self, key: str, message: BaseModel, log_time_ns: int | None = None, views: bool = False
    ) -> None:
        """``message`` as JSON on the channel ``key`` and, if ``views``, its Foxglove views
        (``entries``), logged at its stamp unless given."""
        log_time = stamp_of(message) if log_time_ns is None else log_time_ns
        for entry in entries(key, message, views, self._viewer):
            self.write_raw(entry, log_time)

    def write_raw(self, entry: Entry, log_time_ns: int) -> None:
        """``entry`` on the channel of its key and schema, which is created with its metadata on
        first use (later entries' are then not looked at); published now."""
        schema = (entry.schema_name, entry.schema_encoding, bytes(entry.schema_data))
        channel = self._channels.get((entry.channel, schema))
        if channel is None:
            if schema not in self._schemas:
                self._schemas[schema] = self._writer.register_schema(*schema)
            channel = self._writer.register_channel(
                entry.channel, entry.message_encoding, self._schemas[schema], dict(entry.metadata)
            )
            self._channels[(entry.channel, schema)] = channel
            self._sequences[channel] = 0
        sequence = self._sequences[channel]
        self._sequences[channel] = (sequence + 1) % SEQUENCE_MODULUS
        self._writer.add_message(channel, log_time_ns, entry.data, time.time_ns(), sequence)

    def metadata(self, name: str, values: dict[str, int | str]) -> None:
        """A metadata record ``name`` (the last of a name is the one that holds)."""
        self._writer.add_metadata(name, {k: str(v) for k, v in values.items()})

    def flush(self) -> None:
        """Close the current chunk and push it to the file (no fsync): a kill loses nothing
        written before."""
        if not self._closed:
            self._writer.flush()

    def close(self) -> None:
        """Write the last chunk, the indexes and the footer; later calls do nothing."""
        if not self._closed:
            self._closed = True
            self._writer.finish()
            self._file.close()


@functools.cache
def topic_of(key: str, schema_name: str) -> topics.Topic | None:
    """The topic a project channel carries: its key ends with the suffix, the type matches."""
    for topic in topics.TOPICS.values():
        ends = key == topic.suffix or key.endswith("/" + topic.suffix)
        if ends and topic.type.__name__ == schema_name:
            return topic
    return None
