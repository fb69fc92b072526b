"""A Foxglove live view of a running namespace: foxglove-sdk's WebSocket server, on 127.0.0.1
only, carrying every message of the namespace's topics as it arrives.

Each message goes out as a recording holds it (``record.session_file.entries``): on the channel
of its key as JSON with the project's JSON Schema, and beside it each of its well-known views
(``record.foxglove_views``: ``foxglove.CompressedImage`` or ``RawImage``,
``foxglove.FrameTransforms``, ``foxglove.SceneUpdate``) on ``<key>/foxglove``, logged at the
message's stamp; an image goes once, in its view. A channel is
created, and advertised to the clients, on its first message. A sample that does not decode is
dropped, counted (``malformed``) and said (``parsimony view`` logs it at most once per key every
few seconds).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Sequence
from functools import partial

import foxglove
import zenoh

from messages import codec, topics
from record.session_file import Entry, entries, stamp_of

HOST = "127.0.0.1"
"""The only address the server listens on."""
DEFAULT_PORT = 8765
"""Foxglove's usual WebSocket port."""

log = logging.getLogger(__name__)


class LiveView:
    """The topics ``chosen`` of ``namespace``, read on ``session``, served on ``HOST:port``
    (0: any free port; ``address`` says which). A context manager: ``close`` stops the server
    and the subscriptions. ``shown`` counts the messages logged, ``malformed`` those dropped;
    ``warn(key, text)`` says why a sample was dropped (default: a log warning each time)."""

    def __init__(
        self,
        session: zenoh.Session,
        namespace: str,
        chosen: Sequence[topics.Topic],
        port: int = DEFAULT_PORT,
        warn: Callable[[str, str], None] | None = None,
    ) -> None:
        self._context = foxglove.Context()
        try:
            self._server = foxglove.start_server(name=f"parsimony {namespace}", host=HOST,
                                                 port=port, context=self._context)  # fmt: skip
        except RuntimeError as error:
            raise OSError(f"port: cannot listen on {HOST}:{port}: {error}") from error
        self._channels: dict[tuple[str, str], foxglove.Channel] = {}
        self._lock = threading.Lock()
        self._warn = warn or (lambda _key, message: log.warning("%s", message))
        self.shown = 0
        self.malformed = 0
        self._subscribers = [
            session.declare_subscriber(topic.key(namespace), partial(self._on_sample, topic))
            for topic in chosen
        ]

    @property
    def address(self) -> str:
        """The WebSocket address a Foxglove client opens."""
        return f"ws://{HOST}:{self._server.port}"

    def __enter__(self) -> LiveView:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Stop reading, then stop the server (its clients are disconnected)."""
        for subscriber in self._subscribers:
            subscriber.undeclare()
        self._subscribers = []
        self._server.stop()

    def _on_sample(self, topic: topics.Topic, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        try:
            message = codec.decode(sample.payload.to_bytes(), topic.type, key)
        except codec.DecodeError as error:
            with self._lock:
                self.malformed += 1
                self._warn(key, f"view: malformed sample dropped: {error}")
            return
        stamp = stamp_of(message)
        for entry in entries(key, message):
            self._log(entry, stamp)
        with self._lock:
            self.shown += 1

    def _log(self, entry: Entry, log_time_ns: int) -> None:
        """``entry`` on the channel of its name and schema, created on first use."""
        with self._lock:
            channel = self._channels.get((entry.channel, entry.schema_name))
            if channel is None:
                schema = foxglove.Schema(name=entry.schema_name, encoding=entry.schema_encoding,
                                         data=entry.schema_data)  # fmt: skip
                channel = foxglove.Channel(entry.channel, schema=schema,
                                           message_encoding=entry.message_encoding,
                                           context=self._context,
                                           metadata=dict(entry.metadata))  # fmt: skip
                self._channels[(entry.channel, entry.schema_name)] = channel
        channel.log(entry.data, log_time=log_time_ns)
