"""The simulator's clock."""

from __future__ import annotations

from messages.base import Count, Message


class Clock(Message):
    """Simulated time, published by the simulator each step (``stamp_ns`` in ns), and while it
    is paused (``paused``: the time is held on purpose, not stalled). ``lockstep``: the next step
    waits for the loop's answers, so a time that does not move is the loop's own pace, not a
    stalled simulator."""

    stamp_ns: Count
    paused: bool = False
    lockstep: bool = False
