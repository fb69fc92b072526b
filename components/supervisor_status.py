"""The staging supervisor's status (``supervisor/status``): the goal's phase and why, and its
plan's figures (``components.supervisor``)."""

from __future__ import annotations

from typing import Any

from messages.supervisor import SupervisorStatus
from wbc.planning.staging_supervisor import StagingSupervisor


def supervisor_status(supervisor: StagingSupervisor | None, **fields: Any) -> SupervisorStatus:
    """The status of ``fields`` (header, phase, reason...) with the figures of the pose goal's
    ``supervisor`` (none yet: no candidate, no plan)."""
    if supervisor is None:
        return SupervisorStatus(candidate=0, plans=0, replans=0, stalls=0, **fields)
    candidate = supervisor.candidate
    return SupervisorStatus(
        candidate=len(supervisor.tried),
        candidate_base=None if candidate is None else tuple(candidate.base.tolist()),
        candidate_arm=None if candidate is None else tuple(candidate.arm.tolist()),
        way=tuple(tuple(point.tolist()) for point in supervisor.way()),
        plans=len(supervisor.planning_s),
        replans=supervisor.replans,
        stalls=sum(e.kind == "stall" for e in supervisor.events),
        last_event=supervisor.events[-1].detail if supervisor.events else "",
        planning_ms=supervisor.planning_s[-1] * 1e3 if supervisor.planning_s else None,
        planning_cpu_ms=(
            supervisor.planning_cpu_s[-1] * 1e3 if supervisor.planning_cpu_s else None
        ),
        **fields,
    )
