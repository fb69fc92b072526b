"""Where a recorded run begins and ends: what ``analysis.judge`` judges and a report draws.

The run begins at its first ground truth (its first state on a robot without one) and ends
``HOLD_S`` after the controller's error fell under ``CONVERGED_ERROR`` for good, under a
supervisor within its last pose phase (a drive leg's error is not the goal's); else at the time
limit, or at the last step. Messages stamped far outside the session (``record.session_span``)
are left out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from messages.topics import CONTROL_DIAGNOSTICS, ROBOT_STATE, SIM_TRUTH, SUPERVISOR_STATUS, Topic
from record.session_span import parted
from wbc.planning.supervisor_phase import Phase

Session = Mapping[str, Sequence[Any]]

CONVERGED_ERROR = 0.01
"""The controller's error norm ||e|| under which the goal counts as reached."""
HOLD_S = 2.0
"""Simulated seconds the error must stay under ``CONVERGED_ERROR``; also the steady state."""


def the_run(session: Session, time_limit_s: float | None = None) -> tuple[dict[str, list], bool]:
    """The messages of the run, up to its end (``end_of_run``), and whether it converged: what
    is judged, and what a report draws. Messages stamped far outside the session
    (``record.session_span``) are left out."""
    session = parted(session).kept
    end_ns, converged = end_of_run(session, time_limit_s, origin_s(session))
    return until(session, end_ns), converged


def messages(session: Session, topic: Topic) -> list:
    """The messages of ``topic`` in stamp order (none when the session has none)."""
    return sorted(session.get(topic.name) or [], key=lambda m: m.header.stamp_ns)


def origin_s(session: Session) -> float:
    """When the run began: its first ground truth (0 in lockstep, the host's clock when the
    simulator keeps host time), else its first state; s (inf for an empty session)."""
    first = messages(session, SIM_TRUTH)[:1] or messages(session, ROBOT_STATE)[:1]
    return first[0].header.stamp_ns / 1e9 if first else math.inf


CONVERGING = frozenset(("direct", Phase.POSE, Phase.REACHED))
"""The supervisor's phases in which the controller steps on the goal's own task: a pose goal's
pose phase, a goal of another kind passed on as it is (``direct``), and either once reached."""


def converged_at(diagnostics: Sequence, statuses: Sequence) -> float | None:
    """The time since which every step's error stayed under ``CONVERGED_ERROR``; under a
    supervisor (``statuses``), only the steps of its last run of ``CONVERGING`` phases count."""
    pose_since = pose_phase_since(statuses)
    if pose_since is None:
        return None
    since = None
    for d in diagnostics:
        if d.header.stamp_ns / 1e9 < pose_since:
            continue
        small = d.status == "optimal" and d.error_norm is not None
        if not (small and d.error_norm < CONVERGED_ERROR):
            since = None
        elif since is None:
            since = d.header.stamp_ns / 1e9
    return since


def pose_phase_since(statuses: Sequence) -> float | None:
    """When the supervisor's last run of ``CONVERGING`` phases began; 0 with no supervisor,
    None while it is in another phase."""
    if not statuses:
        return 0.0
    since = None
    for status in statuses:
        if status.phase not in CONVERGING:
            since = None
        elif since is None:
            since = status.header.stamp_ns / 1e9
    return since


def end_of_run(session: Session, time_limit_s: float | None, origin: float) -> tuple[int, bool]:
    """The stamp (ns) the run ends at, ``HOLD_S`` after it converged, else ``time_limit_s``
    after ``origin``, else its last step; and whether it converged. The limit is a simulated
    time, and what came after it is not looked at: two lockstep runs of one set-up judge the
    same steps, however long each went on before it was stopped."""
    limited = time_limit_s is not None and math.isfinite(origin)
    limit_ns = round((origin + time_limit_s) * 1e9) if limited else None
    within = (
        session
        if limit_ns is None
        else until(
            {t.name: session.get(t.name) or [] for t in (CONTROL_DIAGNOSTICS, SUPERVISOR_STATUS)},
            limit_ns,
        )
    )
    diagnostics = messages(within, CONTROL_DIAGNOSTICS)
    since = converged_at(diagnostics, messages(within, SUPERVISOR_STATUS))
    if since is not None and diagnostics[-1].header.stamp_ns / 1e9 - since >= HOLD_S:
        return round((since + HOLD_S) * 1e9), True
    if limit_ns is not None:
        return limit_ns, False
    return (diagnostics[-1].header.stamp_ns if diagnostics else 0), False


def until(session: Session, end_ns: int) -> dict[str, list]:
    """The messages stamped up to ``end_ns``."""
    return {n: [m for m in ms if m.header.stamp_ns <= end_ns] for n, ms in session.items()}
