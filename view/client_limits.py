"""The bounds a client of the live view is held to: how long what it sends may be, how much of
it an answer repeats, and how often it may send a goal.

Nothing a client sends reaches Zenoh, a log line or a status unbounded: a key of more than
64 KiB panics Zenoh's transmission pipeline, and a status goes to every client.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

NAME_CHARS = 128
"""The longest parameter name (``component.name``) a client may give."""
VALUE_CHARS = 4096
"""The longest parameter value, as text, a client may set (a pose is under 100)."""
GOAL_BYTES = 16 * 1024
"""The largest goal message a client may send (a PoseInFrame is about 200 bytes)."""
ECHO_CHARS = 40
"""How much of a client's string an answer repeats."""
STATUS_CHARS = 400
"""The longest status the view sends."""
PARAMETERS_AT_ONCE = 64
"""The most parameters one set may carry (each is a query to its component)."""


def cut(text: str, limit: int) -> str:
    """``text``, or its first ``limit`` characters and how long it was."""
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


def echo(value: object) -> str:
    """A client's value as an answer repeats it: a string quoted and cut, a number in short,
    an object or list by its kind and size (never its nested contents)."""
    if isinstance(value, str):
        return repr(cut(value, ECHO_CHARS))
    if isinstance(value, bool) or value is None:
        return str(value).lower() if value is not None else "null"
    if isinstance(value, int):
        if abs(value) < 10**ECHO_CHARS:
            return str(value)
        return f"an integer of {int(math.log10(abs(value))) + 1} digits"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, bytes):
        return f"{len(value)} bytes"
    if isinstance(value, dict | list | tuple):
        kind = "an object" if isinstance(value, dict) else "a list"
        return f"{kind} of {len(value)} entries"
    return type(value).__name__


@dataclass(frozen=True)
class Rate:
    """At most ``per_s`` a second on average, ``burst`` at once."""

    per_s: float
    burst: int

    def __str__(self) -> str:
        return f"{self.per_s:g} goal/s ({self.burst} at once)"


GOAL_RATE = Rate(per_s=1.0, burst=5)
"""How often one client may send a goal: the supervisor plans anew from each (up to 2 s of
CPU), and a person clicking a pose sends a few a second at most."""
TOLD_EVERY_S = 1.0
"""A client whose goals are dropped for their rate is told so at most this often."""


class Bucket:
    """A token bucket of ``rate`` (one client's goals): ``take`` at host time ``now_s``."""

    def __init__(self, rate: Rate) -> None:
        self.rate = rate
        self._tokens = float(rate.burst)
        self._last_s: float | None = None
        self._told_s: float | None = None
        self.dropped = 0
        """Goals dropped since the client was last told."""

    def take(self, now_s: float) -> bool:
        """Whether a goal at ``now_s`` is within the rate (it then uses a token)."""
        if self._last_s is not None:
            elapsed = max(0.0, now_s - self._last_s)
            self._tokens = min(float(self.rate.burst), self._tokens + elapsed * self.rate.per_s)
        self._last_s = now_s
        if self._tokens >= 1.0:
            self._tokens -= 1.0
            return True
        self.dropped += 1
        return False

    def wait_s(self) -> float:
        """How long until the next goal is within the rate."""
        return max(0.0, (1.0 - self._tokens) / self.rate.per_s)

    def tell(self, now_s: float) -> int:
        """How many goals were dropped since the client was last told, if it is time to tell
        it again (the first drop is told at once), else 0."""
        if self._told_s is not None and now_s - self._told_s < TOLD_EVERY_S:
            return 0
        told, self.dropped, self._told_s = self.dropped, 0, now_s
        return told
