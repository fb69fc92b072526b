"""Typed publishers and subscriptions of a component (see ``components.runtime``).

A subscription keeps only the newest sample waiting for the handler thread,
decodes it there with the codec, drops and counts malformed ones
(``rejected.<topic>``) and counts handler exceptions (``errors.<topic>``).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Generic, TypeVar

import zenoh
from pydantic import BaseModel

from messages import codec, topics
from messages.header import Header

if TYPE_CHECKING:
    from components.runtime import Node

M = TypeVar("M", bound=BaseModel)


class Publisher(Generic[M]):
    """Publishes messages of one topic; ``put`` sets the header's ``seq``.

    A message whose header already carries ``next_seq`` is published as it is; any
    other is copied with the right ``seq`` first.
    """

    def __init__(self, node: Node, topic: topics.Topic[M]) -> None:
        self.topic = topic
        self._node = node
        self._publisher = node.session.declare_publisher(topic.key(node.namespace))
        self._seq = 0
        self._counter = f"published.{topic.name}"
        node.counters[self._counter] = 0

    @property
    def next_seq(self) -> int:
        """The ``seq`` the next ``put`` gives its message's header."""
        return self._seq

    def put(self, message: M) -> None:
        """Encode and publish ``message``, its header's ``seq`` replaced by this topic's count."""
        if not isinstance(message, self.topic.type):
            expected = self.topic.type.__name__
            raise TypeError(f"{self.topic.name} carries {expected}, not {type(message).__name__}")
        header = getattr(message, "header", None)
        if isinstance(header, Header) and header.seq != self._seq:
            stamped = header.model_copy(update={"seq": self._seq})
            message = message.model_copy(update={"header": stamped})
        self._seq += 1
        self._publisher.put(codec.encode(message))
        self._node.counters[self._counter] += 1


class Subscription(Generic[M]):
    """The typed input of one topic: ``latest`` valid message and its ``age_s()``.

    Only the newest sample waits for the handler thread: a sample that arrives
    before the previous one was handled replaces it (``overwritten.<topic>``).
    """

    def __init__(
        self, node: Node, topic: topics.Topic[M], handler: Callable[[M], None] | None
    ) -> None:
        self.topic = topic
        self.latest: M | None = None
        self._node = node
        self._handler = handler
        self._key = topic.key(node.namespace)
        self._lock = threading.Lock()
        self._pending: tuple[bytes, int] | None = None
        self._received_ns: int | None = None
        for kind in ("received", "rejected", "errors", "overwritten"):
            node.counters[f"{kind}.{topic.name}"] = 0
        self._subscriber = node.session.declare_subscriber(self._key, self._on_sample)

    def age_s(self) -> float:
        """Seconds on the component clock since ``latest`` arrived; ``inf`` before the first."""
        if self._received_ns is None:
            return math.inf
        return (self._node.clock.monotonic_ns() - self._received_ns) / 1e9

    def _on_sample(self, sample: zenoh.Sample) -> None:
        """Zenoh thread: keep the newest payload and wake the handler thread."""
        if sample.kind != zenoh.SampleKind.PUT:
            return
        arrival = (sample.payload.to_bytes(), self._node.clock.monotonic_ns())
        with self._lock:
            was_waiting = self._pending is not None
            self._pending = arrival
            if was_waiting:
                self._node.counters[f"overwritten.{self.topic.name}"] += 1
        if not was_waiting:
            self._node.post(self._deliver)

    def _deliver(self) -> None:
        """Handler thread: decode the waiting payload and call the handler."""
        with self._lock:
            pending, self._pending = self._pending, None
        if pending is None:
            return
        payload, arrival_ns = pending
        try:
            message = codec.decode(payload, self.topic.type, self._key)
        except codec.DecodeError as error:
            self._node.counters[f"rejected.{self.topic.name}"] += 1
            self._node.warn(f"rejected.{self.topic.name}", f"dropped a malformed message: {error}")
            return
        self._node.counters[f"received.{self.topic.name}"] += 1
        self.latest, self._received_ns = message, arrival_ns
        if self._handler is None:
            return
        try:
            self._handler(message)
        except Exception:
            self._node.counters[f"errors.{self.topic.name}"] += 1
            self._node.warn(f"errors.{self.topic.name}", f"handler of {self._key} failed", True)
