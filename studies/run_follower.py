"""An experiment's run followed on Zenoh as it goes: its progress printed on stderr, and its
end decided (converged, or its time up); the run itself is judged from its recording."""

from __future__ import annotations

import math
import sys
import threading
import time

import zenoh

from analysis.run_end import HOLD_S, converged_at
from messages import codec, topics
from messages.topics import CONTROL_DIAGNOSTICS, SIM_TRUTH, SUPERVISOR_STATUS

PROGRESS_S = 0.2
"""Host seconds between two looks at the run when no diagnostic arrives (a paused or slow
loop): its time limit and its progress line."""


class Follower:
    """What the run's end is decided on, as it arrives: the controller's diagnostics, the
    supervisor's statuses, and the stamps of the first and the latest ground truth (the
    recording holds everything else; the run is judged from it)."""

    def __init__(self, session: zenoh.Session, namespace: str) -> None:
        self.session: dict[str, list] = {CONTROL_DIAGNOSTICS.name: [], SUPERVISOR_STATUS.name: []}
        self.truth_ns: list[int] = []  # the first and the latest
        self.arrived = threading.Event()
        """Set by each diagnostic or status: the run's end may have come."""
        self._lock = threading.Lock()
        self._subscribers = [
            session.declare_subscriber(topic.key(namespace), self._taker(topic))
            for topic in (CONTROL_DIAGNOSTICS, SUPERVISOR_STATUS, SIM_TRUTH)
        ]

    def _taker(self, topic: topics.Topic):
        def take(sample: zenoh.Sample) -> None:
            message = codec.decode(sample.payload.to_bytes(), topic.type)
            with self._lock:
                if topic is SIM_TRUTH:
                    self.truth_ns[1:] = [message.header.stamp_ns]
                    self.truth_ns[:1] = self.truth_ns[:1] or [message.header.stamp_ns]
                else:
                    self.session[topic.name].append(message)
                    self.arrived.set()

        return take

    def latest(self) -> tuple[dict[str, list], list[int]]:
        """As ``snapshot``, but of the diagnostics only the latest: what the run's progress and
        a first look at its end take, without copying all that came before."""
        with self._lock:
            latest = {
                CONTROL_DIAGNOSTICS.name: self.session[CONTROL_DIAGNOSTICS.name][-1:],
                SUPERVISOR_STATUS.name: list(self.session[SUPERVISOR_STATUS.name]),
            }
            return latest, list(self.truth_ns)

    def snapshot(self) -> tuple[dict[str, list], list[int]]:
        """The diagnostics and statuses so far, and the first and latest truth stamps."""
        with self._lock:
            return {n: list(ms) for n, ms in self.session.items()}, list(self.truth_ns)


def progress_line(session: dict[str, list], origin: float, wall_s: float) -> str:
    diagnostics = session[CONTROL_DIAGNOSTICS.name]
    if not diagnostics:
        return f"[experiment] wall {wall_s:5.1f} s  waiting for the first control step"
    d = diagnostics[-1]
    t = d.header.stamp_ns / 1e9 - min(origin, d.header.stamp_ns / 1e9)
    error = "-" if d.error_norm is None else f"{d.error_norm:.4f}"
    return (
        f"[experiment] sim {t:6.2f} s  wall {wall_s:5.1f} s  error {error}  "
        f"nonzero {d.nonzero}  {d.status}"
    )


def follow(
    follower: Follower, time_limit_s: float, realtime: bool, started: float
) -> tuple[tuple[dict[str, list], list[int]], float]:
    """Print progress until the run converges or its time is up; return what was followed
    (``Follower.snapshot``), and the host seconds since ``started`` when it was. The end is
    looked for as each diagnostic arrives, so that the run is held soon after it (a lockstep
    loop takes a step every few milliseconds); the progress is printed every second."""
    last_print = 0.0
    wall_limit = max(120.0, time_limit_s * (3.0 if realtime else 10.0))
    while True:
        follower.arrived.wait(PROGRESS_S)
        follower.arrived.clear()
        latest, truth_ns = follower.latest()
        origin = truth_ns[0] / 1e9 if truth_ns else math.inf
        wall = time.monotonic() - started
        if wall - last_print >= 1.0:
            print(progress_line(latest, origin, wall), file=sys.stderr, flush=True)
            last_print = wall
        diagnostics, statuses = latest[CONTROL_DIAGNOSTICS.name], latest[SUPERVISOR_STATUS.name]
        now_s = diagnostics[-1].header.stamp_ns / 1e9 if diagnostics else 0.0
        if converged_at(diagnostics, statuses) is not None:  # the latest step counts: look back
            followed, truth_ns = follower.snapshot()
            found = followed[CONTROL_DIAGNOSTICS.name]
            now_s = found[-1].header.stamp_ns / 1e9
            since = converged_at(found, followed[SUPERVISOR_STATUS.name])
            if since is not None and now_s - since >= HOLD_S:
                return (followed, truth_ns), wall
        if now_s - origin >= time_limit_s or wall > wall_limit:
            return follower.snapshot(), wall
