"""The staging supervisor's status carries the figures of its pose goal: none before a goal,
the candidate driven to, its way, the plans and the last event once it has planned."""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.supervisor_status import supervisor_status
from messages.header import Header
from tests.wbc.wbc_scenarios import robot
from wbc.geometry.scenarios import HOME
from wbc.planning.staging_supervisor import StagingSupervisor

MODEL = robot()
HEADER = Header(stamp_ns=5, frame="world", seq=1, source="supervisor")


def test_no_goal_yet_has_no_candidate_and_no_plan() -> None:
    status = supervisor_status(None, header=HEADER, phase="idle", reason="no goal")
    assert (status.candidate, status.plans, status.replans, status.stalls) == (0, 0, 0, 0)
    assert status.candidate_base is None and status.way == () and status.planning_ms is None
    assert (status.header, status.phase, status.reason) == (HEADER, "idle", "no goal")


def test_a_planned_goal_reports_its_candidate_its_way_and_its_plan() -> None:
    goal = MODEL.fkm(np.array([-0.7, 0.3, math.pi - 0.4, 0.2, -0.3, -0.4, 0.2, 0.3]))
    supervisor = StagingSupervisor(MODEL, goal)
    supervisor.step(HOME, 0.0)
    status = supervisor_status(supervisor, header=HEADER, phase=str(supervisor.phase))
    assert status.candidate == 1 and status.plans == 1 and status.replans == 0
    base, arm = status.candidate_base, status.candidate_arm
    assert base is not None and arm is not None and len(base) == 3 and len(arm) == 5
    assert status.phase == "drive" and status.last_event.startswith("drive")  # its latest
    assert status.way[-1] == pytest.approx(base[:2])  # the way ends at the candidate's base
    assert status.planning_ms > 0.0 and status.planning_cpu_ms > 0.0
