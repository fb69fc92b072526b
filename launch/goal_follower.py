"""What the staging supervisor makes of a goal a tool sends, followed on ``supervisor/status``.

A status does not name the goal it is about, so the goal's arrival is read from the
supervisor's own counters: its status is answered on the thread that takes requests, so once
it counts one more request on ``goal/request`` (or one more refused), every
``supervisor/status`` published after is about that goal. Used by ``parsimony goal --wait``.
"""

from __future__ import annotations

import queue
import time
from collections.abc import Callable
from dataclasses import dataclass

import zenoh

from launch.query import QueryError, status_of
from messages import codec, topics
from messages.supervisor import ENDED, IDLE, SupervisorStatus
from wbc.planning.supervisor_phase import Phase

POLL_S = 0.05
"""How often (host seconds) the supervisor's counters are asked while the goal is on its way."""
DONE = (Phase.REACHED.value, Phase.UNREACHABLE.value, *ENDED)
"""The phases that end a goal: each is the goal's outcome."""


@dataclass(frozen=True)
class Outcome:
    """How a goal ended: ``result`` is the phase it ended in (``DONE``), or ``refused`` for a
    request refused as malformed; ``reason`` why it was not reached, ``status`` the last
    status."""

    result: str
    reason: str
    status: SupervisorStatus | None

    @property
    def reached(self) -> bool:
        return self.result == "reached"


class GoalFollower:
    """The statuses of the supervisor ``component`` of ``namespace``, on ``session``: declare
    it before the goal is sent, ``sent`` once it is, then ``follow``."""

    def __init__(
        self, session: zenoh.Session, namespace: str, component: str, timeout_s: float
    ) -> None:
        self.session, self.namespace, self.component = session, namespace, component
        self.timeout_s = timeout_s
        self._key = topics.SUPERVISOR_STATUS.key(namespace)
        self._statuses: queue.Queue[SupervisorStatus] = queue.Queue()
        self._subscriber: zenoh.Subscriber | None = session.declare_subscriber(
            self._key, self._on_status
        )
        self._before = self._requests()
        self._refused = False

    def _on_status(self, sample: zenoh.Sample) -> None:
        try:
            self._statuses.put(codec.decode(sample.payload.to_bytes(), SupervisorStatus, self._key))
        except codec.DecodeError:
            pass  # the supervisor's own counters say it published; a bad one is no answer

    def _requests(self) -> tuple[int, int]:
        """The requests on goal/request the supervisor has taken and refused so far."""
        counters = status_of(self.session, self.namespace, self.component, self.timeout_s).counters
        name = topics.GOAL_REQUEST.name
        return counters.get(f"received.{name}", 0), counters.get(f"rejected.{name}", 0)

    def sent(self) -> None:
        """Wait until the supervisor has the goal just sent (``QueryError`` after
        ``timeout_s``); the statuses published before are dropped."""
        deadline = time.monotonic() + self.timeout_s
        taken, refused = self._before
        while True:
            now_taken, now_refused = self._requests()
            if now_taken > taken or now_refused > refused:
                self._refused = now_refused > refused
                break
            if time.monotonic() > deadline:
                raise QueryError(f"{self.component} did not take the goal in {self.timeout_s:g} s")
            time.sleep(POLL_S)  # asking again: the supervisor answers on its handler thread
        while not self._statuses.empty():
            self._statuses.get_nowait()

    def follow(self, progress: Callable[[SupervisorStatus], None], stamp_ns: int = 0) -> Outcome:
        """Hand each status to ``progress`` until the goal stamped ``stamp_ns`` is reached,
        found unreachable or refused (malformed: the status says why in ``last_refusal``);
        ``QueryError`` when ``timeout_s`` pass with no status. A status of a request taken
        before it (published before the goal was taken, and delivered after) is passed over."""
        while True:
            try:
                status = self._statuses.get(timeout=self.timeout_s)
            except queue.Empty:
                raise QueryError(
                    f"no {self._key} in {self.timeout_s:g} s (is the simulator "
                    "paused, or the state invalid?)"
                ) from None
            if self._refused:
                return Outcome("refused", status.last_refusal, status)
            if status.phase == IDLE or status.request_stamp_ns < stamp_ns:
                continue  # published before the goal was taken, and delivered after
            progress(status)
            if status.phase in DONE:
                return Outcome(status.phase, status.reason, status)

    def close(self) -> None:
        if self._subscriber is not None:
            self._subscriber.undeclare()
            self._subscriber = None
