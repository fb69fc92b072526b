"""A Foxglove live view of a running namespace: foxglove-sdk's WebSocket server, on 127.0.0.1
only, carrying every message of the namespace's topics as it arrives.

Each message goes out as a recording holds it (``record.session_file.entries``): on the channel
of its key as JSON with the project's JSON Schema, and beside it each of its well-known views
(``scenes.foxglove_views.Viewer``: images, frames, the robot drawn from its description,
markers on the image, the supervisor's plan) on ``<key>/<suffix>``, logged at the message's
stamp; an image goes once, in its view. A channel is created, and advertised to the clients,
on its first message. A sample that does not decode is dropped, counted (``malformed``) and
said (``parsimony view`` logs it at most once per key every few seconds).

A client that reads slower than the messages come is shed, not waited for: the server keeps at
most ``BACKLOG`` messages per client and drops the oldest data first (foxglove-sdk's
``message_backlog_size``), so a stalled client costs a bounded memory and never slows the
handlers. The time each sample takes, from its arrival to its last channel's log, is kept
(``handler_us``).

Work nobody reads is not done: once a key has had a message (which opens its channel and those
of all its views, so clients see them), a message of it whose channels no client subscribes to
is dropped undecoded (``unwatched``), and of one that is read only the channels read are made.

What clients may do beyond watching (publish, parameters) is the ``listener``'s, with the
``capabilities`` it needs; this module only serves, and the ``assets`` it is given (URI ->
bytes: the robot's URDF for Foxglove's URDF panel, ``ros2.urdf.assets``) to clients that fetch
them.
"""

from __future__ import annotations

import collections
import logging
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from functools import partial

import foxglove
import numpy as np
import zenoh
from foxglove.websocket import Capability

from messages import codec, topics
from record.session_file import Entry, entries, stamp_of
from scenes.foxglove_views import Viewer, everything, view_channel

HOST = "127.0.0.1"
"""The only address the server listens on."""
DEFAULT_PORT = 8765
"""Foxglove's usual WebSocket port."""
BACKLOG = 256
"""Messages the server holds for one client before it drops the oldest (foxglove-sdk's
default is 1024: 1024 raw 640x480 frames are 300 MB per stalled client)."""
TIMINGS = 100_000
"""The handler times kept, the latest (``handler_us``)."""

log = logging.getLogger(__name__)


class LiveView:
    """The topics ``chosen`` of ``namespace``, read on ``session``, served on ``HOST:port``
    (0: any free port; ``address`` says which). A context manager: ``close`` stops the server
    and the subscriptions. ``shown`` counts the messages logged, ``malformed`` those dropped,
    ``failed`` those whose views could not be made (the message itself is shown);
    ``warn(key, text)`` says why (default: a log warning each time).
    ``viewer`` makes the views (give it the robot description to draw the robot);
    ``listener`` (a ``foxglove.ServerListener``) answers what clients send, with
    ``capabilities`` and the ``encodings`` clients may publish in; ``assets`` what clients may
    fetch, by URI."""

    def __init__(
        self,
        session: zenoh.Session,
        namespace: str,
        chosen: Sequence[topics.Topic],
        port: int = DEFAULT_PORT,
        warn: Callable[[str, str], None] | None = None,
        viewer: Viewer | None = None,
        listener: foxglove.ServerListener | None = None,
        capabilities: Sequence[Capability] = (),
        encodings: Sequence[str] = (),
        assets: Mapping[str, bytes] | None = None,
    ) -> None:
        self._context = foxglove.Context()
        try:
            self.server = foxglove.start_server(
                name=f"parsimony {namespace}",
                host=HOST,
                port=port,
                context=self._context,
                server_listener=listener,
                capabilities=list(capabilities),
                supported_encodings=list(encodings),
                message_backlog_size=BACKLOG,
                asset_handler=dict(assets).get if assets else None,
            )
        except RuntimeError as error:
            raise OSError(f"port: cannot listen on {HOST}:{port}: {error}") from error
        self._viewer = viewer if viewer is not None else Viewer()
        self._channels: dict[tuple[str, str], foxglove.Channel] = {}
        self._by_name: dict[str, foxglove.Channel] = {}
        self._of_key: dict[str, list[foxglove.Channel]] = {}
        """The channels of each key (its message's and its views'), once it has had one."""
        self._lock = threading.Lock()
        self._warn = warn or (lambda _key, message: log.warning("%s", message))
        self._timings: collections.deque[int] = collections.deque(maxlen=TIMINGS)
        self.shown = 0
        self.malformed = 0
        self.failed = 0
        self.unwatched = 0
        self._subscribers = [
            session.declare_subscriber(topic.key(namespace), partial(self._on_sample, topic))
            for topic in chosen
        ]

    @property
    def address(self) -> str:
        """The WebSocket address a Foxglove client opens."""
        return f"ws://{HOST}:{self.server.port}"

    def __enter__(self) -> LiveView:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Stop reading, then stop the server (its clients are disconnected)."""
        for subscriber in self._subscribers:
            subscriber.undeclare()
        self._subscribers = []
        self.server.stop()

    def handler_us(self) -> dict[str, float | int]:
        """The median and p99 of the handler's time per sample, us, over the latest
        ``TIMINGS`` samples, and how many it is over."""
        with self._lock:
            times = np.array(self._timings, dtype=float) / 1e3
        if not len(times):
            return {"samples": 0, "median": 0.0, "p99": 0.0}
        return {
            "samples": len(times),
            "median": round(float(np.median(times)), 1),
            "p99": round(float(np.percentile(times, 99)), 1),
        }

    def _on_sample(self, topic: topics.Topic, sample: zenoh.Sample) -> None:
        started = time.perf_counter_ns()
        key = str(sample.key_expr)
        with self._lock:
            opened = self._of_key.get(key)
        if opened is not None and not any(channel.has_sinks() for channel in opened):
            with self._lock:
                self.unwatched += 1
            return
        try:
            message = codec.decode(sample.payload.to_bytes(), topic.type, key)
        except codec.DecodeError as error:
            with self._lock:
                self.malformed += 1
                self._warn(key, f"view: malformed sample dropped: {error}")
            return
        stamp = stamp_of(message)
        wanted = self._wanted if opened is not None else everything
        try:
            found = entries(key, message, viewer=self._viewer, wanted=wanted)
        except Exception as error:  # a view that fails must not take the others with it
            with self._lock:
                self.failed += 1
                self._warn(
                    key,
                    f"view: no views of a {type(message).__name__} on {key}: "
                    f"{type(error).__name__}: {error}",
                )
            found = entries(key, message, views=False)
        for entry in found:
            self._log(key, entry, stamp)
        if opened is None:
            self._open_the_others(topic, key)
        with self._lock:
            self.shown += 1
            self._timings.append(time.perf_counter_ns() - started)

    def _wanted(self, name: str) -> bool:
        """Whether a channel is to be made: it is not open yet, or a client reads it."""
        channel = self._by_name.get(name)
        return channel is None or channel.has_sinks()

    def _open_the_others(self, topic: topics.Topic, key: str) -> None:
        """After a key's first message: open every view channel it may have, so that a client
        can read one before its first view comes (a robot's model, the plan's scene)."""
        for suffix, kind in self._viewer.channels(topic.name):
            if view_channel(key, suffix) not in self._by_name:
                schema = kind.get_schema()
                self._open(
                    key,
                    view_channel(key, suffix),
                    foxglove.Schema(
                        name=schema.name, encoding=schema.encoding, data=bytes(schema.data)
                    ),
                    "protobuf",
                    {},
                )
        with self._lock:
            self._of_key.setdefault(key, [])

    def _log(self, key: str, entry: Entry, log_time_ns: int) -> None:
        """``entry`` of a message on ``key`` on the channel of its name and schema, opened on
        first use."""
        with self._lock:
            channel = self._channels.get((entry.channel, entry.schema_name))
        if channel is None:
            schema = foxglove.Schema(
                name=entry.schema_name, encoding=entry.schema_encoding, data=entry.schema_data
            )
            channel = self._open(
                key, entry.channel, schema, entry.message_encoding, dict(entry.metadata)
            )
        channel.log(entry.data, log_time=log_time_ns)

    def _open(
        self, key: str, name: str, schema: foxglove.Schema, encoding: str, metadata: dict[str, str]
    ) -> foxglove.Channel:
        """A channel, advertised to the clients, and remembered under its message's key."""
        with self._lock:
            found = self._channels.get((name, schema.name))
            if found is not None:
                return found
            channel = foxglove.Channel(
                name,
                schema=schema,
                message_encoding=encoding,
                context=self._context,
                metadata=metadata,
            )
            self._channels[(name, schema.name)] = channel
            self._by_name.setdefault(name, channel)
            self._of_key.setdefault(key, []).append(channel)
            return channel
