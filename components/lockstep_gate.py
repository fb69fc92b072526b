"""The simulator's lockstep gate: what a step waits for before simulated time goes on.

A step's sensors stamped t are answered by ``base/command`` and ``arm/command`` stamped t (the
controller answers the state of t with the commands of t); a camera frame stamped t by
``vision/markers`` and ``world/markers`` stamped t (``topics.FRAME_ANSWERS``), before the
sensors of t + the camera's latency and before the next frame. The gate keeps the stamps each
topic has answered (``messages.lockstep.AnswerStamps``), the one wait under way and the frame
not yet answered. A wait still open ``timeout_s()`` host seconds after it began is overdue: it
is counted (``lockstep_timeouts``) and given up, and the step goes on. A wait for answers owed
since before a component restarted (``forsake``) is given up sooner, RESTART_GRACE_S after the
restart: the new process never saw what it would have answered (the others' answers still come,
within the grace).

Host time the answers took is kept in ``counters`` (``components.durations``): ``frame``, from
publishing a frame to its last answer; ``frame_wait``, how long a step waited for a frame's
answers; ``loop``, how long it waited for the commands.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from components.durations import Durations
from messages import topics
from messages.lockstep import AnswerStamps

FRAME_ANSWERS = tuple(topic.name for topic in topics.FRAME_ANSWERS)
COMMANDS = (topics.BASE_COMMAND.name, topics.ARM_COMMAND.name)
RESTART_GRACE_S = 2.0
"""Host seconds the answers owed since before a restart may still take (a restarted process owes
none of them; the others answer in milliseconds)."""


@dataclass(frozen=True)
class Awaited:
    """The answers a step waits for: the stamps of ``topics`` that must reach ``stamp_ns``,
    since ``since`` and until ``deadline`` (host seconds)."""

    stamp_ns: int
    topics: tuple[str, ...]
    since: float
    deadline: float

    @property
    def frame(self) -> bool:
        """A wait for a camera frame's answers (else for the commands)."""
        return self.topics == FRAME_ANSWERS


@dataclass(frozen=True)
class Frame:
    """A camera frame published and not yet answered, and when (host seconds)."""

    stamp_ns: int
    published: float


class LockstepGate:
    """The answers a lockstep simulator waits for (see the module docstring)."""

    def __init__(
        self,
        counters: dict[str, int],
        latency_ns: int,
        timeout_s: Callable[[], float],
        host_clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.latency_ns = latency_ns
        self.timeout_s = timeout_s
        self.host_clock = host_clock
        self.answers = AnswerStamps()
        self.awaited: Awaited | None = None
        self.unanswered: Frame | None = None
        self.forsaken: tuple[int, str, float] | None = None
        """The last stamp awaited when a component restarted, its name and when (``forsake``)."""
        self._counters = counters
        self._times = {k: Durations(counters, k) for k in ("frame", "frame_wait", "loop")}
        counters["lockstep_timeouts"] = 0

    @property
    def waiting(self) -> bool:
        """A step waits for answers."""
        return self.awaited is not None

    def frame_taken(self, stamp_ns: int) -> None:
        """A frame stamped ``stamp_ns`` was handed to the camera: it awaits its answers."""
        self.unanswered = Frame(stamp_ns, self.host_clock())

    def frame_due(self, now_ns: int) -> bool:
        """Whether the step of ``now_ns`` must wait for the last frame's answers before its
        sensors (the frame's latency has passed): if so, the wait begins. An answered frame is
        forgotten."""
        frame = self.unanswered
        if frame is not None and self.answers.answered(frame.stamp_ns, FRAME_ANSWERS):
            self.unanswered = frame = None
        if frame is None or frame.stamp_ns + self.latency_ns > now_ns:
            return False
        self.wait(FRAME_ANSWERS, frame.stamp_ns)
        return True

    def frame_pending(self) -> bool:
        """Whether the next frame must wait for the last one's answers: if so, the wait
        begins."""
        if self.unanswered is None:
            return False
        self.wait(FRAME_ANSWERS, self.unanswered.stamp_ns)
        return True

    def wait(self, names: tuple[str, ...], stamp_ns: int) -> None:
        """Begin waiting for ``names`` to answer ``stamp_ns``."""
        now = self.host_clock()
        self.awaited = Awaited(stamp_ns, names, now, now + self.timeout_s())

    def note(self, name: str, stamp_ns: int) -> Awaited | None:
        """``name`` answered with ``stamp_ns``; the wait it completes (now over), if any."""
        self.answers.note(name, stamp_ns)
        frame = self.unanswered
        if (
            name in FRAME_ANSWERS
            and frame is not None
            and self.answers.answered(frame.stamp_ns, FRAME_ANSWERS)
        ):
            self._times["frame"].note(self.host_clock() - frame.published)
        return self.check()

    def check(self) -> Awaited | None:
        """The wait under way, over if every answer it waits for is in; else None."""
        awaited = self.awaited
        if awaited is None or not self.answers.answered(awaited.stamp_ns, awaited.topics):
            return None
        kind = "frame_wait" if awaited.frame else "loop"
        self._times[kind].note(self.host_clock() - awaited.since)
        return self._release()

    def forsake(self, name: str) -> None:
        """Component ``name`` restarted: the answers awaited now (the wait under way and the frame
        not yet answered) are owed for stamps it never saw; a wait for them is given up
        RESTART_GRACE_S after this (``overdue``)."""
        owed = [item.stamp_ns for item in (self.awaited, self.unanswered) if item is not None]
        if self.forsaken is not None:
            owed.append(self.forsaken[0])
        if owed:
            self.forsaken = (max(owed), name, self.host_clock())

    def overdue(self) -> tuple[Awaited, list[str], str | None] | None:
        """The wait under way, the topics that have not answered and the component whose restart
        forsook it (None: its deadline passed), given up and counted once its deadline has passed
        or, its stamp forsaken (``forsake``), the restart's grace; else None."""
        awaited, forsaken, now = self.awaited, self.forsaken, self.host_clock()
        if awaited is None:
            return None
        restarted = None
        if forsaken and awaited.stamp_ns <= forsaken[0] and now > forsaken[2] + RESTART_GRACE_S:
            restarted = forsaken[1]
        if restarted is None and now <= awaited.deadline:
            return None
        missing = self.answers.missing(awaited.stamp_ns, awaited.topics)
        self._counters["lockstep_timeouts"] += 1
        return self._release(), missing, restarted

    def _release(self) -> Awaited:
        awaited, self.awaited = self.awaited, None
        assert awaited is not None
        if awaited.frame:
            self.unanswered = None
        return awaited
