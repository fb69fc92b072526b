"""Typed publishers and subscriptions of a component (see ``components.runtime``).

A subscription hands its samples to the component's handler thread and decodes them there
with the codec; it drops and counts malformed ones (``rejected.<topic>``), refuses a payload
over the topic's ``max_bytes`` on arrival, before any copy or decoding (counted the same), and
counts handler exceptions (``errors.<topic>``); a refusal is logged once per failing check and
handed to the component's ``on_reject``, if it gave one; ``handler.<topic>_us_median`` and
``_us_p99`` say how long its handler takes (``components.durations``). Each input chooses what
waits for the handler:

- ``latest`` (control): only the newest sample; one that arrives before the previous was
  handled replaces it (``overwritten.<topic>``);
- ``queue=N`` (a recorder, an estimator): every sample in arrival order, at most N waiting;
  past that the oldest is dropped (``overflowed.<topic>``). Nothing is lost uncounted.
"""

from __future__ import annotations

import collections
import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Generic, Protocol, TypeVar

import zenoh
from pydantic import BaseModel

from components.clock import Clock
from components.durations import Durations
from messages import codec, topics
from messages.header import Header

M = TypeVar("M", bound=BaseModel)


class Host(Protocol):
    """What publishers and subscriptions need of their component's runtime (a ``Node``)."""

    namespace: str
    counters: dict[str, int]
    clock: Clock

    @property
    def session(self) -> zenoh.Session: ...

    def post(self, event: Callable[[], None]) -> None: ...

    def warn(self, kind: str, message: str, exc_info: bool = False) -> None: ...


@dataclass(frozen=True)
class Input:
    """A topic a component reads, and what waits for its handler: the newest sample only
    (``queue`` None) or every sample in order, at most ``queue`` waiting."""

    topic: topics.Topic
    queue: int | None = None

    def __post_init__(self) -> None:
        if self.queue is not None and self.queue < 1:
            raise ValueError(f"{self.topic.name}: a queue holds >= 1 sample, got {self.queue}")

    def describe(self) -> str:
        """``robot/state (newest)`` or ``robot/state (queue 100)``."""
        mode = "newest" if self.queue is None else f"queue {self.queue}"
        return f"{self.topic.name} ({mode})"


class Publisher(Generic[M]):
    """Publishes messages of one topic; ``put`` sets the header's ``seq``.

    A message whose header already carries ``next_seq`` is published as it is; any other is
    copied with the right ``seq`` first. (A replay publishes recorded headers as they are with
    Zenoh's own publishers: ``record.replayer``.)
    """

    def __init__(self, node: Host, topic: topics.Topic[M]) -> None:
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
        """Encode and publish ``message``, its header's ``seq`` replaced by this topic's
        count."""
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

    ``queue`` None keeps only the newest sample waiting; ``queue`` N keeps every sample in
    order, at most N waiting (see the module's docstring).
    """

    def __init__(
        self,
        node: Host,
        topic: topics.Topic[M],
        handler: Callable[[M], None] | None,
        queue: int | None = None,
        on_reject: Callable[[str], None] | None = None,
    ) -> None:
        Input(topic, queue)  # checks the queue
        self.topic = topic
        self.latest: M | None = None
        self._node = node
        self._handler = handler
        self._on_reject = on_reject
        self._key = topic.key(node.namespace)
        self._lock = threading.Lock()
        self._waiting: collections.deque[tuple[bytes, int]] = collections.deque()
        self._capacity = 1 if queue is None else queue
        self._dropped = f"{'overwritten' if queue is None else 'overflowed'}.{topic.name}"
        self._received_ns: int | None = None
        self._oversized_warning_waiting = False
        for kind in ("received", "rejected", "errors"):
            node.counters[f"{kind}.{topic.name}"] = 0
        node.counters[self._dropped] = 0
        self._handler_time = Durations(node.counters, f"handler.{topic.name}")
        # indirect=False: called on the Zenoh thread that received the sample, so the samples of
        # one publisher's session reach the handler in the order they were put, across topics
        # (zenoh-python's default runs each subscriber's callback on a thread of its own).
        on_sample = zenoh.handlers.Callback(self._on_sample, indirect=False)
        self._subscriber = node.session.declare_subscriber(self._key, on_sample)

    def age_s(self) -> float:
        """Seconds on the component clock since ``latest`` arrived; ``inf`` before the first."""
        if self._received_ns is None:
            return math.inf
        return (self._node.clock.monotonic_ns() - self._received_ns) / 1e9

    def _on_sample(self, sample: zenoh.Sample) -> None:
        """Zenoh thread: keep the payload (dropping the oldest when full), wake the handler."""
        if sample.kind != zenoh.SampleKind.PUT:
            return
        size = len(sample.payload)
        if size > self.topic.max_bytes:
            self._refuse_oversized(size)
            return
        arrival = (sample.payload.to_bytes(), self._node.clock.monotonic_ns())
        with self._lock:
            was_idle = not self._waiting
            self._waiting.append(arrival)
            if len(self._waiting) > self._capacity:
                self._waiting.popleft()
                self._node.counters[self._dropped] += 1
        if was_idle:
            self._node.post(self._deliver)

    def _refuse_oversized(self, size: int) -> None:
        """Zenoh thread: count a payload over the topic's ``max_bytes``, never decoding it; the
        warning is logged by the handler thread, one at a time whatever the flood."""
        with self._lock:
            self._node.counters[f"rejected.{self.topic.name}"] += 1
            warn = not self._oversized_warning_waiting
            self._oversized_warning_waiting = True
        if warn:
            self._node.post(partial(self._warn_oversized, size))

    def _warn_oversized(self, size: int) -> None:
        with self._lock:
            self._oversized_warning_waiting = False
        self._reject(
            "size",
            f"dropped a {size}-byte message on {self._key}: over {self.topic.max_bytes} bytes",
        )

    def _reject(self, check: str, reason: str) -> None:
        """Handler thread: log a refusal, rate-limited per topic and check (so that each
        failing check is heard), and tell the component."""
        self._node.warn(f"rejected.{self.topic.name}.{check}", reason)
        if self._on_reject is not None:
            try:
                self._on_reject(reason)
            except Exception:
                self._node.counters[f"errors.{self.topic.name}"] += 1
                self._node.warn(
                    f"errors.{self.topic.name}", f"refusal handler of {self._key} failed", True
                )

    def drain(self) -> None:
        """Handler thread: deliver every sample still waiting (a recorder closing its file)."""
        while self._waiting:
            self._deliver()

    def _deliver(self) -> None:
        """Handler thread: decode the oldest waiting payload and call the handler; come back
        for the next one after the events already waiting (so timers keep their turn)."""
        with self._lock:
            if not self._waiting:
                return
            payload, arrival_ns = self._waiting.popleft()
            more = bool(self._waiting)
        if more:
            self._node.post(self._deliver)
        try:
            message = codec.decode(payload, self.topic.type, self._key)
        except codec.DecodeError as error:
            self._node.counters[f"rejected.{self.topic.name}"] += 1
            self._reject(error.field or "message", f"dropped a malformed message: {error}")
            return
        self._node.counters[f"received.{self.topic.name}"] += 1
        self.latest, self._received_ns = message, arrival_ns
        if self._handler is None:
            return
        started = time.perf_counter()
        try:
            self._handler(message)
            self._handler_time.note(time.perf_counter() - started)
        except Exception:
            self._node.counters[f"errors.{self.topic.name}"] += 1
            self._node.warn(f"errors.{self.topic.name}", f"handler of {self._key} failed", True)
