"""Sessions as MCAP files: one channel per key expression, every channel with its schema.

The project's messages go in as JSON (message encoding ``json``, schema encoding
``jsonschema``, schema name the type's name, schema data its JSON Schema, ``bytes`` fields as
base64 strings marked ``"contentEncoding": "base64"``), so Foxglove plots them as they are, and
come back into their pydantic types exactly: Python writes a float as its shortest repr, which
reads back bit for bit. Beside a message go its Foxglove views (``record.foxglove_views``), when
asked for, on channels of their own. Each image is stored once: a view that carries a field as
it is (a frame's JPEG or pixels in its ``foxglove.CompressedImage`` or ``RawImage``) holds it,
and the message's JSON leaves it out; the channel's metadata names the carrier
(``CARRIED_FIELD``, ``CARRIER``), and reading puts the field back from the view of the same
log time. Other channels are written as given (``write_raw``). Chunks are zstd-compressed;
``flush`` closes the current one and pushes it to the file, so a writer killed by SIGKILL loses
only what came after its last flush.

A file without a footer (its writer was killed) is read record by record with the streaming
reader up to its last complete chunk: ``read_session`` and ``info`` work on it as they are, and
``recover`` writes a whole file (footer, indexes, statistics) from it.
"""

from __future__ import annotations

import base64
import functools
import heapq
import json
import logging
import struct
import time
from array import array
from collections.abc import Collection, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from mcap.exceptions import EndOfFile, InvalidMagic, McapError
from mcap.records import Channel, Chunk, Footer, Message, Metadata, Schema
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import MCAP0_MAGIC, CompressionType, Writer
from pydantic import BaseModel

from messages import topics
from messages.schema import json_schema
from record.foxglove_views import View, carried, views_of

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
``overwritten.<topic>``), those that are not 0; written as they change and at the end."""


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

    A bytes field (an image) is neither copied by ``model_dump`` nor scanned by ``json.dumps``:
    a marker holds its place, then gives it to the base64 text, which needs no escaping.
    """
    names = [name for name in bytes_fields(type(message)) if name != left_out]
    dumped = message.model_dump(exclude={*bytes_fields(type(message)), left_out})
    fields = {name: BYTES_MARKER if name in names else dumped[name]
              for name in type(message).model_fields if name != left_out}  # fmt: skip
    text = json.dumps(fields, allow_nan=False, separators=(",", ":")).encode()
    for name in names:
        value = b'"' + base64.b64encode(getattr(message, name)) + b'"'
        text = text.replace(_ENCODED_MARKER, value, 1)
    return text


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


def entries(key: str, message: BaseModel, views: bool = True) -> list[Entry]:
    """A project message on ``key`` as a session (or a live view) holds it: its JSON on the
    channel ``key``, then, if ``views``, each Foxglove view on its own channel; a field that a
    view carries is left out of the JSON, which names the carrier in its metadata."""
    found: list[View] = []
    if views:
        topic = _topic_of(key, type(message).__name__)
        found = views_of(topic.name, key, message) if topic is not None else []
    carrier = next((v for v in found if v.carries), None)
    left_out = carrier.carries if carrier is not None else ""
    metadata = ((CARRIED_FIELD, left_out), (CARRIER, carrier.channel(key)[0])) if left_out else ()
    own = Entry(key, type(message).__name__, SCHEMA_ENCODING, schema_of(type(message), left_out),
                MESSAGE_ENCODING, to_json(message, left_out), metadata)  # fmt: skip
    return [own, *(Entry(*v.channel(key)) for v in found)]


def from_json(
    data: bytes, message_type: type[BaseModel], carried_fields: dict[str, bytes] | None = None
) -> BaseModel:
    """The message ``to_json`` wrote, exactly (``model_validate`` of the decoded JSON), with
    the fields it left out taken from ``carried_fields``."""
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

    ``chunk_size`` is the uncompressed size (bytes) at which a chunk is closed on its own.
    """

    def __init__(self, path: Path, chunk_size: int = 1024 * 1024) -> None:
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
        for entry in entries(key, message, views):
            self.write_raw(entry, log_time)

    def write_raw(self, entry: Entry, log_time_ns: int) -> None:
        """``entry`` on the channel of its key and schema, which is created with its metadata on
        first use (later entries' are then not looked at); published now."""
        schema = (entry.schema_name, entry.schema_encoding, bytes(entry.schema_data))
        channel = self._channels.get((entry.channel, schema))
        if channel is None:
            if schema not in self._schemas:
                self._schemas[schema] = self._writer.register_schema(*schema)
            channel = self._writer.register_channel(entry.channel, entry.message_encoding,
                                                    self._schemas[schema], dict(entry.metadata))
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


class _ExactReads:
    """A binary file whose ``read(n)`` gives ``n`` bytes or raises ``EndOfFile``.

    mcap's reader passes short reads on, so the cut of a file without a footer would surface
    as a struct, zstd or UTF-8 error depending on where it fell; through this it is always
    ``EndOfFile``, and every other fault stays an error.
    """

    def __init__(self, stream: IO[bytes]) -> None:
        self._stream = stream

    def read(self, length: int) -> bytes:
        data = self._stream.read(length)
        if len(data) < length:
            raise EndOfFile()
        return data


log = logging.getLogger("record")


class _Scan:
    """``(schema or None, channel, message)`` of every readable chunk of a file, in file order.

    Reading stops quietly where a file without a footer was cut (``EndOfFile``). A chunk that
    does not decompress or fails its CRC is skipped, and said in ``damaged`` (with the times of
    the messages it held) and in a warning. A file that does not begin as an MCAP file, and a
    fault outside the chunks, raise ``McapError`` naming the file. After iterating,
    ``complete`` says whether the footer was there.

    The data section is a sequence of units, each a chunk or a message outside any chunk:
    ``units`` gives each unit's messages, ``unit_starts`` each unit's earliest log time without
    decompressing anything (a chunk's header says it), so a reader can merge them in log-time
    order holding only the units whose times overlap (``read_groups``).
    """

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.complete = False
        self.damaged: list[str] = []
        self.metadata: dict[str, dict[str, str]] = {}

    def __iter__(self) -> Iterator[tuple[Schema | None, Channel, Message]]:
        for unit in self.units():
            yield from unit

    def units(self) -> Iterator[list[tuple[Schema | None, Channel, Message]]]:
        """The messages of each unit (a chunk, or a message outside the chunks), in file order;
        a damaged chunk gives an empty unit."""
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        for record in self._records():
            inner = self._opened(record) if isinstance(record, Chunk) else [record]
            found = [f for f in (self._take(item, schemas, channels) for item in inner) if f]
            if isinstance(record, (Chunk, Message)):
                yield found

    def unit_starts(self) -> array:
        """The earliest log time of each unit, as its header says (nothing decompressed)."""
        starts = array("q")
        for record in self._records():
            if isinstance(record, Chunk):
                starts.append(record.message_start_time)
            elif isinstance(record, Message):
                starts.append(record.log_time)
            elif isinstance(record, Footer):
                self.complete = True
        return starts

    def _records(self) -> Iterator[Any]:
        """The file's records, chunks unopened, the file's faults turned into ``McapError``."""
        with self.path.open("rb") as stream:
            reader = StreamReader(_ExactReads(stream), emit_chunks=True)
            begun = False
            try:
                for record in reader.records:
                    begun = True  # the magic and the header were there
                    yield record
            except InvalidMagic:
                raise McapError(f"{self.path}: not an MCAP file") from None
            except EndOfFile:
                stream.seek(0)
                start = stream.read(len(MCAP0_MAGIC))
                if not begun and not MCAP0_MAGIC.startswith(start):
                    raise McapError(f"{self.path}: not an MCAP file") from None
                return  # cut short, maybe before anything was written
            except (struct.error, UnicodeDecodeError, ValueError) as error:
                raise McapError(f"{self.path}: damaged outside its chunks: {error}") from None

    def _opened(self, chunk: Chunk) -> list:
        """A chunk's records, or none when it is damaged (said)."""
        try:
            return breakup_chunk(chunk, validate_crc=True)
        except Exception as error:  # noqa: BLE001 - zstandard's, mcap's CRC, struct's: all mean one thing
            what = (f"the chunk of {chunk.message_start_time / 1e9:.3f} to "
                    f"{chunk.message_end_time / 1e9:.3f} s ({error or type(error).__name__})")
            self.damaged.append(what)
            log.warning("%s: skipped %s", self.path, what)
            return []

    def _take(self, record, schemas: dict, channels: dict):
        if isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, Channel):
            if record.schema_id != 0 and record.schema_id not in schemas:
                raise McapError(f"{self.path}: channel {record.topic!r} has no schema record "
                                f"{record.schema_id}")  # fmt: skip
            channels[record.id] = record
        elif isinstance(record, Message):
            channel = channels.get(record.channel_id)
            if channel is None:
                raise McapError(f"{self.path}: message on unknown channel {record.channel_id}")
            return schemas.get(channel.schema_id), channel, record
        elif isinstance(record, Footer):
            self.complete = True
        elif isinstance(record, Metadata):
            self.metadata[record.name] = dict(record.metadata)
        return None


@functools.cache
def _topic_of(key: str, schema_name: str) -> topics.Topic | None:
    """The topic a project channel carries: its key ends with the suffix, the type matches."""
    for topic in topics.TOPICS.values():
        ends = key == topic.suffix or key.endswith("/" + topic.suffix)
        if ends and topic.type.__name__ == schema_name:
            return topic
    return None


def _project_topic(schema: Schema | None, channel: Channel) -> topics.Topic | None:
    if schema is None or channel.message_encoding != MESSAGE_ENCODING:
        return None
    return _topic_of(channel.topic, schema.name)


def read_session(path: Path, only: Collection[str] | None = None) -> Iterator[Recorded]:
    """Every message of a session file, in log-time order (``read_groups``, flattened)."""
    for group in read_groups(path, only):
        yield from group


def read_groups(path: Path, only: Collection[str] | None = None) -> Iterator[list[Recorded]]:
    """The messages of a session file (all its complete chunks if it has no footer) in
    log-time order, one list per log time, in file order within it. The project's messages
    are decoded into their types, a field carried by a view put back; other channels'
    messages (the Foxglove views) come with ``topic_name`` and ``message`` None. Given
    ``only`` (topic names), only those topics' messages come, and nothing else is decoded.

    The file is streamed: a first pass reads each unit's earliest time from its header
    (``_Scan.unit_starts``); the second opens the units in file order and gives a log time
    once no later unit can start at or before it, so only units whose times overlap are held,
    whatever the file's length.

    In a file cut short, a message whose carrier was cut off is left out; in a whole file, it
    is an ``McapError``. A message that does not decode into its type is left out and said
    (the first of each channel, where and why, then how many); so is a damaged chunk
    (``_Scan``)."""
    headers = _Scan(path)
    starts = headers.unit_starts()
    later = array("q", starts) + array("q", [2**63 - 1])  # the earliest start from unit i on
    for i in range(len(starts) - 1, -1, -1):
        later[i] = min(later[i], later[i + 1])
    pending: list = []  # (log time, unit, place in the unit, found): file order among ties
    skipped: dict[str, int] = {}
    for index, unit in enumerate(_Scan(path).units()):
        for place, found in enumerate(unit):
            heapq.heappush(pending, (found[2].log_time, index, place, found))
        while pending and pending[0][0] < later[index + 1]:
            log_time = pending[0][0]
            group = []
            while pending and pending[0][0] == log_time:
                group.append(heapq.heappop(pending)[3])
            if decoded := _decoded(path, group, only, headers.complete, skipped):
                yield decoded
    for key, count in skipped.items():
        if count > 1:
            log.warning("%s: skipped %d messages of %s in all", path, count, key)


def _decoded(path: Path, group: list, only: Collection[str] | None, complete: bool,
             skipped: dict[str, int]) -> list[Recorded]:  # fmt: skip
    """The messages of one log time as ``Recorded``, each carried field taken from its
    carrier among them; those that do not decode left out, said once per channel and counted
    in ``skipped``."""
    carriers = {channel.topic: (schema, message) for schema, channel, message in group}
    out = []
    for schema, channel, message in group:
        topic = _project_topic(schema, channel)
        if only is not None and (topic is None or topic.name not in only):
            continue
        decoded = None
        if topic is not None:
            carried_fields = _carried_fields(channel, carriers)
            if carried_fields is None:
                if complete:
                    raise McapError(f"{path}: {channel.topic} at {message.log_time} ns has no "
                                    f"{channel.metadata[CARRIER]} message")  # fmt: skip
                continue
            try:
                decoded = from_json(message.data, topic.type, carried_fields)
            except ValueError as error:  # JSON's, base64's and pydantic's errors are ValueErrors
                skipped[channel.topic] = skipped.get(channel.topic, 0) + 1
                if skipped[channel.topic] == 1:
                    _skipped(path, channel.topic, message.log_time, topic.type, error)
                continue
        out.append(Recorded(channel.topic, topic.name if topic else None, message.log_time,
                            decoded))  # fmt: skip
    return out


def _skipped(path: Path, key: str, log_time_ns: int, expected: type, error: Exception) -> None:
    """Say that a message was left out because it does not decode, where and why."""
    reason = str(error).splitlines()[0] if str(error) else type(error).__name__
    log.warning("%s: skipped the message of %s at %.3f s: not a %s (%s)", path, key,
                log_time_ns / 1e9, expected.__name__, reason)  # fmt: skip


def _carried_fields(channel: Channel, carriers: dict[str, tuple]) -> dict[str, bytes] | None:
    """The fields of a project message that its channel's carrier holds (none for a channel
    without one), or None when the carrier has no message of its log time (``carriers``: the
    messages of that log time by key)."""
    if CARRIER not in channel.metadata:
        return {}
    found = carriers.get(channel.metadata[CARRIER])
    if found is None:
        return None
    schema, view = found
    return {channel.metadata[CARRIED_FIELD]: carried(schema.name, view.data)}


def info(path: Path) -> dict[str, Any]:
    """What a session file holds: totals (messages, file bytes, start, end and duration,
    ``complete``: whether the footer is there, ``damaged``: the chunks skipped, ``dropped``:
    the samples its recorder lost, by counter, ``DROPPED``) and, per
    channel, its key, the project topic it carries (None for a view or a foreign channel),
    schema name, encoding and size in bytes, message count and bytes, first
    and last log time and mean rate (Hz, (count - 1) / span)."""
    scan = _Scan(path)
    channels: dict[int, dict[str, Any]] = {}
    for schema, channel, message in scan:
        entry = channels.get(channel.id)
        if entry is None:
            topic = _project_topic(schema, channel)
            entry = channels[channel.id] = {
                "key": channel.topic,
                "topic": topic.name if topic is not None else None,
                "schema": schema.name if schema is not None else "",
                "schema_encoding": schema.encoding if schema is not None else "",
                "schema_bytes": len(schema.data) if schema is not None else 0,
                "encoding": channel.message_encoding,
                "messages": 0,
                "bytes": 0,
                "start_ns": message.log_time,
                "end_ns": message.log_time,
            }
        entry["messages"] += 1
        entry["bytes"] += len(message.data)
        entry["start_ns"] = min(entry["start_ns"], message.log_time)
        entry["end_ns"] = max(entry["end_ns"], message.log_time)
    for entry in channels.values():
        span_s = (entry["end_ns"] - entry["start_ns"]) / 1e9
        entry["rate_hz"] = round((entry["messages"] - 1) / span_s, 2) if span_s > 0 else 0.0
    start = min((c["start_ns"] for c in channels.values()), default=0)
    end = max((c["end_ns"] for c in channels.values()), default=0)
    return {
        "path": str(path),
        "complete": scan.complete,
        "damaged": scan.damaged,
        "dropped": {key: int(n) for key, n in scan.metadata.get(DROPPED, {}).items()},
        "messages": sum(c["messages"] for c in channels.values()),
        "bytes": Path(path).stat().st_size,
        "start_ns": start,
        "end_ns": end,
        "duration_s": round((end - start) / 1e9, 3),
        "channels": sorted(channels.values(), key=lambda c: c["key"]),
    }


def recover(source: Path, target: Path) -> int:
    """Write at ``target`` a whole file (footer, indexes, statistics) of every message that
    survives in ``source`` (a file without a footer, or a whole one), schemas, channels,
    times and sequence numbers unchanged, in file order, with the last metadata record of each
    name (``DROPPED``: what the recorder lost); return the number of messages."""
    if Path(source).resolve() == Path(target).resolve():
        raise ValueError(f"recover: {source} would be overwritten while it is read")
    schema_ids: dict[int, int] = {0: 0}
    channel_ids: dict[int, int] = {}
    saved = 0
    with Path(target).open("wb") as stream:
        writer = Writer(stream, compression=CompressionType.ZSTD)
        writer.start(library=LIBRARY)
        scan = _Scan(source)
        for schema, channel, message in scan:
            if schema is not None and schema.id not in schema_ids:
                schema_ids[schema.id] = writer.register_schema(
                    schema.name, schema.encoding, schema.data
                )
            if channel.id not in channel_ids:
                channel_ids[channel.id] = writer.register_channel(
                    channel.topic, channel.message_encoding, schema_ids[channel.schema_id],
                    channel.metadata,
                )  # fmt: skip
            writer.add_message(channel_ids[channel.id], message.log_time, message.data,
                               message.publish_time, message.sequence)  # fmt: skip
            saved += 1
        for name, values in scan.metadata.items():
            writer.add_metadata(name, values)
        writer.finish()
    return saved
