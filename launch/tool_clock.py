"""The profile's clock as a tool reads it, to stamp the headers it makes.

On a profile whose ``clock`` is ``wall``, the host's Unix time; on a ``sim`` one, the latest
``sim/clock`` stamp of its namespace (the simulator publishes it every step, and while paused):
a header stamped with the wall clock there lies decades after the session, and a recording
that holds it would seem to last that long. Used by ``parsimony topic pub``, ``parsimony goal``
and the live view's control station.
"""

from __future__ import annotations

import threading
import time

import zenoh

from launch.query import QueryError
from messages import codec, topics
from messages.header import Header
from profiles.profile import Profile


class NoClock(QueryError):
    """A sim-clock profile whose simulator's clock has not reached the tool."""


class ToolClock:
    """The time of ``profile``'s clock, seen on ``session``; ``close`` (or the end of a
    ``with`` block) undeclares its subscriber."""

    def __init__(self, session: zenoh.Session, profile: Profile) -> None:
        self.simulated = profile.clock == "sim"
        self._key = topics.SIM_CLOCK.key(profile.namespace)
        self._stamp_ns: int | None = None
        self._arrived = threading.Event()
        self._subscriber = (
            session.declare_subscriber(self._key, self._on_clock) if self.simulated else None
        )

    def _on_clock(self, sample: zenoh.Sample) -> None:
        try:
            clock = codec.decode(sample.payload.to_bytes(), topics.SIM_CLOCK.type, self._key)
        except codec.DecodeError:
            return  # not a time to stamp with; the components on this clock say so
        self._stamp_ns = clock.stamp_ns
        self._arrived.set()

    def now_ns(self) -> int | None:
        """The clock's time in ns: Unix time, or the simulator's (None before its first
        ``sim/clock`` came)."""
        return self._stamp_ns if self.simulated else time.time_ns()

    def wait_ns(self, timeout_s: float) -> int:
        """``now_ns``, waiting up to ``timeout_s`` for the simulator's first clock
        (``NoClock`` if it does not come)."""
        if self.simulated and not self._arrived.wait(timeout_s):
            raise NoClock(
                f"no simulator clock on {self._key} in {timeout_s:g} s: a sim-clock "
                "profile's messages are stamped on it (is the simulator running?)"
            )
        stamp_ns = self.now_ns()
        assert stamp_ns is not None
        return stamp_ns

    def header(self, seq: int, source: str, timeout_s: float, frame: str = "world") -> Header:
        """A header stamped now on this clock (``wait_ns``)."""
        return Header(stamp_ns=self.wait_ns(timeout_s), frame=frame, seq=seq, source=source)

    def close(self) -> None:
        if self._subscriber is not None:
            self._subscriber.undeclare()
            self._subscriber = None

    def __enter__(self) -> ToolClock:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()
