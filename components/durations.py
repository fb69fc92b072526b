"""Recent durations of one kind of work, summarised as integer counters of a component status.

    durations.note(seconds)  ->  counters["<name>_us_median"], counters["<name>_us_p99"]

over the last ``WINDOW`` notes, refreshed every ``EVERY`` notes (and on each of the first), so
that ``parsimony node info`` and the experiment reports show how long a handler takes.
"""

from __future__ import annotations

import collections

WINDOW = 2000
EVERY = 50


class Durations:
    """The median and p99 of recent durations, in microseconds, kept in ``counters``."""

    def __init__(self, counters: dict[str, int], name: str) -> None:
        self._counters = counters
        self._median, self._p99 = f"{name}_us_median", f"{name}_us_p99"
        self._recent: collections.deque[float] = collections.deque(maxlen=WINDOW)
        self._notes = 0

    def note(self, seconds: float) -> None:
        self._recent.append(seconds * 1e6)
        self._notes += 1
        if self._notes < EVERY or self._notes % EVERY == 0:
            ordered = sorted(self._recent)
            self._counters[self._median] = round(ordered[len(ordered) // 2])
            self._counters[self._p99] = round(
                ordered[min(len(ordered) - 1, int(len(ordered) * 0.99))]
            )
