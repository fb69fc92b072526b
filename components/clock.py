"""A component's clock and timers: wall time, or the simulator's time from ``sim/clock``.

Both clocks give two readings. ``now_ns`` stamps messages (Unix time, or
simulated time). ``monotonic_ns`` measures periods and ages (``time.monotonic``,
or simulated time again), so a wall-clock step never stalls a timer.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass


class WallClock:
    """The host's clocks."""

    simulated = False

    def now_ns(self) -> int:
        """Unix time in ns, for stamps."""
        return time.time_ns()

    def monotonic_ns(self) -> int:
        """Monotonic time in ns, for periods and ages."""
        return time.monotonic_ns()


class SimClock:
    """The simulator's time: zero until the first ``sim/clock`` message, then its stamp.

    ``advance`` is called on the handler thread; reading an int is safe from any thread.
    ``stalled_s`` measures, on the host's monotonic clock, how long the time has not moved
    (a paused simulator's clock does not stall).
    """

    simulated = True

    def __init__(self) -> None:
        self._stamp_ns = 0
        self._moved_at_ns = time.monotonic_ns()
        self.started = False
        """Whether a ``sim/clock`` message has come."""
        self._lockstep = False

    def advance(self, stamp_ns: int, paused: bool = False, lockstep: bool = False) -> None:
        """Set the time to ``stamp_ns`` (it may go back when a replay restarts). A paused
        simulator holds its time on purpose, and a lockstep one waits for the loop's answers
        (its own timeout bounds that wait): neither clock counts as stalled. Its first tick
        starts it: the time before counts as no stall."""
        if stamp_ns != self._stamp_ns or paused or not self.started:
            self._moved_at_ns = time.monotonic_ns()
        self.started = True
        self._stamp_ns = stamp_ns
        self._lockstep = lockstep

    def stalled_s(self) -> float:
        """Host seconds since the simulated time last moved (or since its first tick); 0
        in lockstep, where a component's command on a stall would be taken as the step's."""
        if self._lockstep:
            return 0.0
        return (time.monotonic_ns() - self._moved_at_ns) / 1e9

    def now_ns(self) -> int:
        """Simulated time in ns."""
        return self._stamp_ns

    def monotonic_ns(self) -> int:
        """Simulated time in ns."""
        return self._stamp_ns


Clock = WallClock | SimClock

STALL_CHECK_S = 0.05
"""How often (host seconds) a component on simulated time checks that its clock still moves."""


@dataclass
class Timer:
    """A callback due every ``period_ns`` on a clock's monotonic time."""

    period_ns: int
    callback: Callable[[], None]
    deadline_ns: int

    @property
    def name(self) -> str:
        """The callback's name, for logs and counters."""
        return getattr(self.callback, "__qualname__", repr(self.callback))

    def reschedule(self, now_ns: int) -> bool:
        """Move the deadline if the timer is due; return whether it was.

        A due timer moves one period on, skipping missed periods. A deadline
        more than a period away means the clock was set back: it restarts from now.
        """
        if self.deadline_ns <= now_ns:
            self.deadline_ns += self.period_ns
            if self.deadline_ns <= now_ns:
                self.deadline_ns = now_ns + self.period_ns
            return True
        if self.deadline_ns > now_ns + self.period_ns:
            self.deadline_ns = now_ns + self.period_ns
        return False


@dataclass
class Alarm:
    """A callback due once, ``after_s`` from when it was last ``set`` on a clock's monotonic
    time; ``set`` again moves the deadline, ``cancel`` clears it (a command timeout)."""

    clock: Clock
    callback: Callable[[], None]
    deadline_ns: int | None = None

    @property
    def name(self) -> str:
        return getattr(self.callback, "__qualname__", repr(self.callback))

    def set(self, after_s: float) -> None:
        self.deadline_ns = self.clock.monotonic_ns() + max(0, round(after_s * 1e9))

    def cancel(self) -> None:
        self.deadline_ns = None

    def reschedule(self, now_ns: int) -> bool:
        """Whether the alarm is due; a due alarm is cleared."""
        if self.deadline_ns is None or self.deadline_ns > now_ns:
            return False
        self.deadline_ns = None
        return True


class Timers:
    """The timers and alarms of one component, fired by its handler thread."""

    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self._timers: list[Timer | Alarm] = []

    def add(self, period_s: float, callback: Callable[[], None]) -> Timer:
        """Call ``callback`` every ``period_s`` seconds of the clock, first after one period."""
        if not period_s > 0.0:
            raise ValueError(f"timer period must be > 0 s, got {period_s}")
        period_ns = max(1, round(period_s * 1e9))
        timer = Timer(period_ns, callback, self.clock.monotonic_ns() + period_ns)
        self._timers.append(timer)
        return timer

    def alarm(self, callback: Callable[[], None]) -> Alarm:
        """An alarm that calls ``callback`` once per ``Alarm.set``."""
        alarm = Alarm(self.clock, callback)
        self._timers.append(alarm)
        return alarm

    def due(self) -> list[Timer | Alarm]:
        """The timers and alarms whose deadline has passed, each moved to its next deadline."""
        now = self.clock.monotonic_ns()
        return [timer for timer in self._timers if timer.reschedule(now)]

    def wait_s(self) -> float | None:
        """How long the handler thread may block before a timer is due.

        ``None`` (block until the next event) when nothing is due. On a simulated clock, time
        only moves with a ``sim/clock`` message, so the thread wakes every ``STALL_CHECK_S`` of
        host time to notice a clock that stopped.
        """
        if self.clock.simulated:
            return STALL_CHECK_S
        deadlines = [t.deadline_ns for t in self._timers if t.deadline_ns is not None]
        if not deadlines:
            return None
        return max(0.0, (min(deadlines) - self.clock.monotonic_ns()) / 1e9)
