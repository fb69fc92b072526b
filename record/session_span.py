"""A session's span, and the stamps far outside it.

A stamp on another clock than the session's (a wall-clock stamp in a simulated session, whose
time starts at 0; a stamp of 0 in a session on host time) lies decades from the others. Every
reader of a session (the recorder, ``info``, ``replay``, ``report``, the judge) follows one
rule: the session is the stretch of stamps without a gap of more than ``FAR_NS`` that holds
the most messages (the earliest of equals); a stamp outside that stretch is far outside the
session: said in one line naming its topic (``outside_line``), and left out.

Stamps are counted in bins ``FAR_NS`` wide (no gap within a bin can exceed it), so a ``Span``
holds a few numbers per bin, however long the session.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from record.session_file import stamp_of

FAR_NS = 86_400 * 10**9
"""A gap of stamps wider than this (a day) parts the session from what is far outside it: a
recording never pauses for a day, and a clock mix-up is decades."""


class Span:
    """Stamps counted by bin; ``session`` is the rule's stretch of them."""

    def __init__(self) -> None:
        self._bins: dict[int, list[int]] = {}  # bin -> [messages, first stamp, last stamp]

    def add(self, stamp_ns: int) -> None:
        found = self._bins.get(stamp_ns // FAR_NS)
        if found is None:
            self._bins[stamp_ns // FAR_NS] = [1, stamp_ns, stamp_ns]
        else:
            found[0] += 1
            found[1] = min(found[1], stamp_ns)
            found[2] = max(found[2], stamp_ns)

    def session(self) -> tuple[int, int]:
        """The first and last stamp of the session ((0, 0) with no stamp)."""
        stretches: list[list[int]] = []
        for index in sorted(self._bins):
            count, first, last = self._bins[index]
            if stretches and first - stretches[-1][2] <= FAR_NS:
                stretches[-1][0] += count
                stretches[-1][2] = last
            else:
                stretches.append([count, first, last])
        best = max(stretches, key=lambda s: s[0], default=[0, 0, 0])  # the first of equals
        return best[1], best[2]


def inside(stamp_ns: int, session: tuple[int, int]) -> bool:
    """Whether ``stamp_ns`` is within the session's span."""
    return session[0] <= stamp_ns <= session[1]


def outside_line(outside: Mapping[str, tuple[int, int]], session: tuple[int, int]) -> str:
    """One line of what is far outside ``session``: by topic, (messages, first stamp)."""
    parts = [
        f"{count} message{'s' * (count != 1)} of {topic} (at {first / 1e9:.3f} s"
        f"{' first' if count > 1 else ''})"
        for topic, (count, first) in sorted(outside.items())
    ]
    return (
        f"stamped far outside the session ({session[0] / 1e9:.3f} to "
        f"{session[1] / 1e9:.3f} s): {', '.join(parts)}"
    )


@dataclass(frozen=True)
class Parted:
    """A session (topic name -> messages) parted by the rule: the messages within its
    ``span`` and those far ``outside`` it, each by topic (only topics with some outside in
    the second)."""

    kept: dict[str, list]
    outside: dict[str, list]
    span: tuple[int, int]

    def line(self) -> str | None:
        """``outside_line`` of what is outside, None when nothing is."""
        if not self.outside:
            return None
        counted = {t: (len(ms), min(stamp_of(m) for m in ms)) for t, ms in self.outside.items()}
        return outside_line(counted, self.span)


def parted(session: Mapping[str, Sequence[Any]]) -> Parted:
    """``session`` parted into what is within its span and what is far outside it."""
    span = Span()
    for found in session.values():
        for message in found:
            span.add(stamp_of(message))
    bounds = span.session()
    kept: dict[str, list] = {}
    outside: dict[str, list] = {}
    for topic, found in session.items():
        kept[topic] = [m for m in found if inside(stamp_of(m), bounds)]
        if len(kept[topic]) < len(found):
            outside[topic] = [m for m in found if not inside(stamp_of(m), bounds)]
    return Parted(kept, outside, bounds)
