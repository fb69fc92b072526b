"""Session files read back: streamed in log-time order, described, made whole.

A file without a footer (its writer was killed) is read record by record with mcap's streaming
reader up to its last complete chunk: ``read_session`` and ``info`` work on it as it is, and
``recover`` writes a whole file (footer, indexes, statistics) from it. The format is
``record.session_file``'s.
"""

from __future__ import annotations

import heapq
import logging
import struct
from array import array
from collections.abc import Collection, Iterator
from pathlib import Path
from typing import IO, Any

from mcap.exceptions import EndOfFile, InvalidMagic, McapError
from mcap.records import Channel, Chunk, Footer, Message, Metadata, Schema
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import MCAP0_MAGIC, CompressionType, Writer

from messages import topics
from record.session_file import (
    CARRIED_FIELD,
    CARRIER,
    DROPPED,
    LIBRARY,
    MESSAGE_ENCODING,
    Recorded,
    from_json,
    topic_of,
)
from record.session_span import FAR_NS, Span, inside, outside_line
from scenes.foxglove_views import carried


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
            what = (
                f"the chunk of {chunk.message_start_time / 1e9:.3f} to "
                f"{chunk.message_end_time / 1e9:.3f} s ({error or type(error).__name__})"
            )
            self.damaged.append(what)
            log.warning("%s: skipped %s", self.path, what)
            return []

    def _take(self, record, schemas: dict, channels: dict):
        if isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, Channel):
            if record.schema_id != 0 and record.schema_id not in schemas:
                raise McapError(
                    f"{self.path}: channel {record.topic!r} has no schema record {record.schema_id}"
                )
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


def _project_topic(schema: Schema | None, channel: Channel) -> topics.Topic | None:
    if schema is None or channel.message_encoding != MESSAGE_ENCODING:
        return None
    return topic_of(channel.topic, schema.name)


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


def _decoded(
    path: Path, group: list, only: Collection[str] | None, complete: bool, skipped: dict[str, int]
) -> list[Recorded]:
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
                    raise McapError(
                        f"{path}: {channel.topic} at {message.log_time} ns has no "
                        f"{channel.metadata[CARRIER]} message"
                    )
                continue
            try:
                decoded = from_json(message.data, topic.type, carried_fields)
            except ValueError as error:  # JSON's, base64's and pydantic's errors are ValueErrors
                skipped[channel.topic] = skipped.get(channel.topic, 0) + 1
                if skipped[channel.topic] == 1:
                    _skipped(path, channel.topic, message.log_time, topic.type, error)
                continue
        out.append(
            Recorded(channel.topic, topic.name if topic else None, message.log_time, decoded)
        )
    return out


def _skipped(path: Path, key: str, log_time_ns: int, expected: type, error: Exception) -> None:
    """Say that a message was left out because it does not decode, where and why."""
    reason = str(error).splitlines()[0] if str(error) else type(error).__name__
    log.warning(
        "%s: skipped the message of %s at %.3f s: not a %s (%s)",
        path,
        key,
        log_time_ns / 1e9,
        expected.__name__,
        reason,
    )


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
    and last log time and mean rate (Hz, (count - 1) / span).

    Messages logged far outside the session (``record.session_span``) are left out of all
    of that and counted in ``outside``, by key: messages and first log time; ``warning`` says
    so in one line (None when there are none)."""
    scan = _Scan(path)
    span = Span()
    channels: dict[int, dict[str, Any]] = {}
    bins: dict[tuple[int, int], list[int]] = {}  # (channel, bin): messages, bytes, first, last
    for schema, channel, message in scan:
        if channel.id not in channels:
            topic = _project_topic(schema, channel)
            channels[channel.id] = {
                "key": channel.topic,
                "topic": topic.name if topic is not None else None,
                "schema": schema.name if schema is not None else "",
                "schema_encoding": schema.encoding if schema is not None else "",
                "schema_bytes": len(schema.data) if schema is not None else 0,
                "encoding": channel.message_encoding,
            }
        span.add(message.log_time)
        counted = bins.setdefault(
            (channel.id, message.log_time // FAR_NS), [0, 0, message.log_time, message.log_time]
        )
        counted[0] += 1
        counted[1] += len(message.data)
        counted[2] = min(counted[2], message.log_time)
        counted[3] = max(counted[3], message.log_time)
    session = span.session()
    totals: dict[int, list[int]] = {}
    outside: dict[str, list[int]] = {}
    for (channel_id, _), (count, size, first, last) in bins.items():
        if inside(first, session):  # a bin is wholly inside the session or wholly out
            total = totals.setdefault(channel_id, [0, 0, first, last])
            total[0] += count
            total[1] += size
            total[2], total[3] = min(total[2], first), max(total[3], last)
        else:
            far = outside.setdefault(channels[channel_id]["key"], [0, first])
            far[0] += count
            far[1] = min(far[1], first)
    for channel_id, entry in channels.items():
        count, size, first, last = totals.get(channel_id, [0, 0, 0, 0])
        span_s = (last - first) / 1e9
        entry.update(
            messages=count,
            bytes=size,
            start_ns=first,
            end_ns=last,
            rate_hz=round((count - 1) / span_s, 2) if span_s > 0 else 0.0,
        )
    return {
        "path": str(path),
        "complete": scan.complete,
        "damaged": scan.damaged,
        "dropped": {key: int(n) for key, n in scan.metadata.get(DROPPED, {}).items()},
        "messages": sum(c["messages"] for c in channels.values()),
        "bytes": Path(path).stat().st_size,
        "start_ns": session[0],
        "end_ns": session[1],
        "duration_s": round((session[1] - session[0]) / 1e9, 3),
        "channels": sorted(channels.values(), key=lambda c: c["key"]),
        "outside": {key: {"messages": n, "first_ns": first} for key, (n, first) in outside.items()},
        "warning": outside_line({k: tuple(v) for k, v in outside.items()}, session)
        if outside
        else None,
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
                    channel.topic,
                    channel.message_encoding,
                    schema_ids[channel.schema_id],
                    channel.metadata,
                )
            writer.add_message(
                channel_ids[channel.id],
                message.log_time,
                message.data,
                message.publish_time,
                message.sequence,
            )
            saved += 1
        for name, values in scan.metadata.items():
            writer.add_metadata(name, values)
        writer.finish()
    return saved


def make_whole(path: Path) -> int:
    """Make ``path``, whose writer was killed before the footer, whole in place: every
    complete chunk kept (``recover``), written beside it and renamed onto it; the number of
    messages kept."""
    partial = path.with_name(f".{path.name}.whole")
    saved = recover(path, partial)
    partial.replace(path)
    return saved
