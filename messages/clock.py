"""The simulator's clock."""

from __future__ import annotations

from messages.base import Count, Message


class Clock(Message):
    """Simulated time, published by the simulator each step (``stamp_ns`` in ns), and while it
    is paused (``paused``: the time is held on purpose, not stalled)."""

    stamp_ns: Count
    paused: bool = False
