"""The runtime every component process shares: one process is one component.

A component module defines a ``Component`` subclass and ends with::

    if __name__ == "__main__":
        run_component(MyComponent)  # components.process_entry

It runs as ``python -m components.<module> --profile PATH --name NAME``. The
``Node`` gives it a Zenoh session opened from the profile, typed publishers
and subscriptions (names from ``messages.topics``), declared parameters,
timers on the profile's clock, counters, a liveliness token, and queryables
that answer its status and get or set its parameters.

Every handler, timer and query runs on one handler thread, one at a time, so
component code needs no locks. A malformed message is dropped, counted as
``rejected.<topic>`` and logged (rate-limited); an exception in a handler is
counted as ``errors.<topic>``; the process keeps running either way.
"""

from __future__ import annotations

import logging
import os
import queue
import threading
import time
from collections.abc import Callable, Iterable
from functools import partial
from pathlib import Path
from typing import ClassVar, TypeVar

import zenoh
from pydantic import BaseModel

from components.clock import Alarm, Clock, SimClock, Timer, Timers, WallClock
from components.params import Param, ParamError, Parameters, keep_params, restore_params
from components.pubsub import Input, Publisher, Subscription
from components.rate_limited_log import RateLimitedLog
from messages import codec, topics
from messages.header import Header
from messages.process import encode_value
from messages.status import ComponentStatus
from messages.stop import StopState
from profiles.profile import Profile

M = TypeVar("M", bound=BaseModel)

STOP_MARGIN_S = 1.0
"""The handler thread gets the profile's ``stop_timeout_s`` less this to finish (after which
the launcher kills the process) before the session closes anyway."""

log = logging.getLogger("components")


WAITING_FOR_CLOCK = "waiting for the clock"
"""A recorder's state on simulated time before the clock's first tick."""


class Node:
    """One component's runtime: session, parameters, clock, timers, counters, handler thread.

    Use as a context manager: entering opens the Zenoh session, ``start()``
    makes the component visible and starts handling, leaving closes it all.
    """

    def __init__(
        self,
        profile: Profile,
        name: str,
        params: Iterable[Param] = (),
        reads: Iterable[Input] | None = None,
        writes: Iterable[topics.Topic] | None = None,
        kept_params: Path | None = None,
        session: zenoh.Session | None = None,
    ) -> None:
        """Raise ``KeyError`` for a name not in the profile, ``ParamError`` for bad params.

        ``reads`` and ``writes`` are the component's declared topics (``Component.reads``,
        ``Component.writes``): when given, the node refuses any other, and each subscription
        takes its mode from its declaration. ``None`` (a test's or a tool's node) allows any.
        ``kept_params`` is a JSON file of the parameters set at run time by an earlier run of
        this component: they are set again (over the profile's), and later changes written back.
        ``session``, when given, is a session the node uses and leaves open (the one of the
        components sharing a process, ``components.container``) instead of one of its own.
        """
        self.reads = None if reads is None else {i.topic.name: i for i in reads}
        self.writes = None if writes is None else {t.name for t in writes}
        self.profile = profile
        self.spec = profile.component(name)
        self.name = name
        self.namespace = profile.namespace
        self.params = Parameters(params, self.spec.params)
        self._kept_params = kept_params
        if kept_params is not None:
            restore_params(self.params, kept_params)
        publishes_clock = self.writes is not None and topics.SIM_CLOCK.name in self.writes
        source = profile.clock_of(self.spec, publishes_clock)
        self.clock: Clock = SimClock() if source == "sim" else WallClock()
        self.counters: dict[str, int] = {"clock_stalls": 0}
        self.state = "starting"
        self.stop: StopState | None = None
        """The emergency stop this component holds (``components.stop_latch``), if it does."""
        self.failure: str | None = None
        """Why this component stopped for good (``fail``); the process exits non-zero."""
        self.stop_requested = threading.Event()
        self._timers = Timers(self.clock)
        self._events: queue.SimpleQueue[Callable[[], None] | None] = queue.SimpleQueue()
        self._warnings = RateLimitedLog(log)
        self._session: zenoh.Session | None = None
        self._lent = session
        self._declared: list[object] = []
        self._thread: threading.Thread | None = None
        self._on_shutdown: Callable[[], None] | None = None
        self._on_clock_stall: Callable[[float], None] | None = None

    def __enter__(self) -> Node:
        self._session = self._lent or zenoh.open(self.profile.zenoh.component_config(self.name))
        clock = self.clock
        if isinstance(clock, SimClock):
            self.subscribe(
                topics.SIM_CLOCK,
                lambda tick: clock.advance(tick.stamp_ns, tick.paused, tick.lockstep),
            )
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    @property
    def session(self) -> zenoh.Session:
        """The open Zenoh session."""
        if self._session is None:
            raise RuntimeError("the node's session is not open; use `with Node(...) as node`")
        return self._session

    def publisher(self, topic: topics.Topic[M]) -> Publisher[M]:
        """A typed publisher on ``topic`` in this node's namespace, declared until close."""
        if self.writes is not None and topic.name not in self.writes:
            raise ValueError(f"{self.name} writes {topic.name} without declaring it in `writes`")
        publisher = Publisher(self, self.spec.topic(topic))
        self._declared.append(publisher)
        return publisher

    def subscribe(
        self,
        topic: topics.Topic[M],
        handler: Callable[[M], None] | None = None,
        queue: int | None = None,
        on_reject: Callable[[str], None] | None = None,
    ) -> Subscription[M]:
        """Subscribe to ``topic`` until close; ``handler`` (optional) gets each valid message,
        ``on_reject`` (optional) the reason of each refused one.

        ``queue`` None hands the handler the newest sample only (control inputs); N hands it
        every sample in order, at most N waiting (see ``components.pubsub``). A component
        declares it in ``reads``, and the node takes it from there.
        """
        actual = self.spec.topic(topic)
        if actual.ground_truth and self.spec.role in ("estimator", "controller"):
            raise ValueError(
                f"{self.name} is an {self.spec.role}: it may not read the ground "
                f"truth on {actual.name}"
            )
        if self.reads is not None and topic.name in self.reads:
            queue = self.reads[topic.name].queue  # sim/clock too, when declared (a recorder)
        elif self.reads is not None and topic is not topics.SIM_CLOCK:
            raise ValueError(f"{self.name} reads {topic.name} without declaring it in `reads`")
        subscription = Subscription(self, actual, handler, queue, on_reject)
        self._declared.append(subscription)
        return subscription

    def timer(self, period_s: float, callback: Callable[[], None]) -> Timer:
        """Call ``callback`` on the handler thread every ``period_s`` of the component clock."""
        timer = self._timers.add(period_s, callback)
        self.counters[f"errors.timer.{timer.name}"] = 0
        return timer

    def alarm(self, callback: Callable[[], None]) -> Alarm:
        """An alarm that calls ``callback`` on the handler thread once, ``after_s`` of the
        component clock from each ``alarm.set(after_s)``."""
        alarm = self._timers.alarm(callback)
        self.counters[f"errors.timer.{alarm.name}"] = 0
        return alarm

    def header(self, frame: str = "", stamp_ns: int | None = None, seq: int = 0) -> Header:
        """A header from this component, stamped now unless ``stamp_ns`` is given.

        ``Publisher.put`` sets ``seq``; passing the publisher's ``next_seq`` spares it a copy.
        """
        stamp = self.clock.now_ns() if stamp_ns is None else stamp_ns
        return Header(stamp_ns=stamp, frame=frame, seq=seq, source=self.name)

    def count(self, counter: str, amount: int = 1) -> None:
        """Add ``amount`` to a component counter (handler thread only)."""
        self.counters[counter] = self.counters.get(counter, 0) + amount

    def warn(self, kind: str, message: str, exc_info: bool = False) -> None:
        """Log a warning, rate-limited per ``kind`` (handler thread only)."""
        self._warnings.warning(kind, message, exc_info)

    def status(self) -> ComponentStatus:
        """This component's self-report."""
        return ComponentStatus(
            header=self.header(),
            name=self.name,
            module=self.spec.module,
            state=self.state
            if self.stop is None or not self.stop.stopped
            else f"{self.state}, stopped by {self.stop.header.source}",
            pid=os.getpid(),
            counters={**self.counters, "cpu_ms": round(time.process_time() * 1e3)},
            parameters=dict(self.params),
            stop=self.stop,
        )

    def fail(self, reason: str) -> None:
        """Stop this component for good: log ``reason``; the process then exits with
        ``EXIT_FOR_GOOD`` and is not restarted."""
        log.error("%s: %s", self.name, reason)
        self.failure = reason
        self.state = "failed"
        self.stop_requested.set()

    def post(self, event: Callable[[], None]) -> None:
        """Run ``event`` on the handler thread (callable from any thread)."""
        self._events.put(event)

    def start(
        self,
        on_shutdown: Callable[[], None] | None = None,
        on_clock_stall: Callable[[float], None] | None = None,
    ) -> None:
        """Answer queries, start the handler thread and declare the liveliness token.

        ``on_shutdown`` runs on the handler thread when the node closes; ``on_clock_stall``
        when a simulated clock has not moved for the profile's ``clock_timeout_s`` (host
        seconds), with that duration.
        """
        self._on_shutdown = on_shutdown
        self._on_clock_stall = on_clock_stall
        session = self.session
        status_key = topics.status_key(self.namespace, self.name)
        param_keys = {topics.param_key(self.namespace, self.name, p): p for p in self.params}
        self._declared += [
            session.declare_queryable(
                status_key, lambda query: self.post(partial(self._answer_status, query))
            ),
            session.declare_queryable(
                topics.param_selector(self.namespace, self.name),
                lambda query: self.post(partial(self._answer_param, query, param_keys)),
            ),
        ]
        self._thread = threading.Thread(
            target=self._handle, name=f"{self.name}-handler", daemon=True
        )
        self._thread.start()
        self.state = "running"
        self._declared.append(
            session.liveliness().declare_token(topics.liveliness_key(self.namespace, self.name))
        )
        log.info("%s running (%s, pid %d)", self.name, self.spec.module_path, os.getpid())

    def close(self) -> None:
        """Stop the handler thread (after ``on_shutdown``) and close the session."""
        self.state = "stopping"
        if self._thread is not None:
            self._events.put(None)
            # A recorder writes all that waits (the launcher kills it if it stops progressing).
            recorder = self.spec.role == "recorder"
            patience_s = None if recorder else max(0.5, self.spec.stop_timeout_s - STOP_MARGIN_S)
            self._thread.join(patience_s)
            if self._thread.is_alive():
                log.warning("handler thread busy after %.1f s; closing anyway", patience_s)
        if self._session is not None and self._lent is None:
            self._session.close()
        self._declared.clear()

    def _handle(self) -> None:
        """The handler thread: run events and due timers one at a time until closed."""
        while True:
            try:
                event = self._events.get(timeout=self._timers.wait_s())
            except queue.Empty:
                pass
            else:
                if event is None:
                    break
                self._run(event, "errors.events")
            for timer in self._timers.due():
                self._run(timer.callback, f"errors.timer.{timer.name}")
            self._check_clock()
        if self._on_shutdown is not None:
            self._run(self._on_shutdown, "errors.shutdown")

    def _check_clock(self) -> None:
        """On simulated time: say so, once, when the clock stops moving, and when it moves again.
        A component is ``WAITING_FOR_CLOCK`` until the clock's first tick: a clock that has not
        started has not stalled (nothing simulated moves before it starts, and a zero command
        stamped 0 from a component that started before the simulator would make a lockstep
        run's commands depend on the order the processes came up)."""
        clock = self.clock
        if not isinstance(clock, SimClock):
            return
        if not clock.started:
            if self.state == "running":
                self.state = WAITING_FOR_CLOCK
            return
        if self.state == WAITING_FOR_CLOCK:
            self.state = "running"
        stalled_s = clock.stalled_s()
        if stalled_s >= self.profile.clock_timeout_s and self.state == "running":
            self.state = "clock stalled"
            self.count("clock_stalls")
            log.warning("%s: sim/clock has not moved for %.2f s", self.name, stalled_s)
            if self._on_clock_stall is not None:
                self._run(partial(self._on_clock_stall, stalled_s), "errors.clock_stall")
        elif stalled_s < self.profile.clock_timeout_s and self.state == "clock stalled":
            self.state = "running"
            log.info("%s: sim/clock moves again", self.name)

    def _run(self, callback: Callable[[], None], counter: str) -> None:
        try:
            callback()
        except Exception:
            self.count(counter)
            self.warn(counter, f"{getattr(callback, '__qualname__', callback)} failed", True)

    def _answer_status(self, query: zenoh.Query) -> None:
        with query:
            status = self.status()
            query.reply(topics.status_key(self.namespace, self.name), codec.encode(status))

    def _answer_param(self, query: zenoh.Query, keys: dict[str, str]) -> None:
        """Reply every parameter the query's key matches; set it first if there is a payload."""
        with query:
            matching = {key: name for key, name in keys.items() if query.key_expr.intersects(key)}
            try:
                if not matching:
                    raise ParamError(
                        f"{self.name} has no parameter at {query.key_expr}; "
                        f"declared: {', '.join(self.params) or 'none'}"
                    )
                if query.payload is not None:
                    if len(matching) != 1:
                        raise ParamError(f"set one parameter at a time; {query.key_expr} is many")
                    (name,) = matching.values()
                    value = self.params.set_text(name, query.payload.to_string())
                    log.info("parameter %s set to %r", name, value)
                    if self._kept_params is not None:
                        keep_params(self.params, self._kept_params)
            except ParamError as error:
                query.reply_err(str(error))
                return
            for key, name in matching.items():
                query.reply(key, encode_value(self.params[name]))


class Component:
    """Base of every component: declare ``params``, ``reads`` and ``writes``, build
    publishers, subscriptions and timers on ``self.node`` in ``__init__``, react in handlers.

    ``__init__`` raises ``ParamError`` for a parameter value it cannot use (a missing
    file, say): the process then exits with ``EXIT_CONFIG_ERROR`` and is not restarted."""

    params: ClassVar[tuple[Param, ...]] = ()
    reads: ClassVar[tuple[Input, ...]] = ()
    """The topics this component subscribes to, each with its mode (the graph's inputs)."""
    writes: ClassVar[tuple[topics.Topic, ...]] = ()
    """The topics this component publishes (the graph's outputs)."""

    def __init__(self, node: Node) -> None:
        self.node = node

    def shutdown(self) -> None:
        """Runs on the handler thread before the session closes (a driver stops the robot here)."""

    def clock_stalled(self, stalled_s: float) -> None:
        """Runs on the handler thread when the simulated clock stopped for ``stalled_s`` host
        seconds (a controller commands zero here)."""
