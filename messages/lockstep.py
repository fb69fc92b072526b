"""The lockstep handshake, acknowledged by stamps: a message stamped t is answered on the
topics ``names`` once each has carried a stamp >= t (the simulator waits so for its loop, a
replay under ``--lockstep`` for the live tracker and estimator)."""

from __future__ import annotations

from collections.abc import Iterable


class AnswerStamps:
    """The latest stamp seen on each answering topic."""

    def __init__(self) -> None:
        self._stamps: dict[str, int] = {}

    def note(self, name: str, stamp_ns: int) -> None:
        """``name`` carried ``stamp_ns`` (an older stamp does not move it back)."""
        self._stamps[name] = max(self._stamps.get(name, -1), stamp_ns)

    def missing(self, stamp_ns: int, names: Iterable[str]) -> list[str]:
        """The topics of ``names`` that have not yet answered ``stamp_ns``."""
        return [name for name in names if self._stamps.get(name, -1) < stamp_ns]

    def answered(self, stamp_ns: int, names: Iterable[str]) -> bool:
        return not self.missing(stamp_ns, names)

    def forget(self) -> None:
        """Forget every answer (a replay going back to its start)."""
        self._stamps.clear()
