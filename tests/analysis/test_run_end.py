"""analysis.run_end on sessions of real kinematic runs of the LP (tests/analysis/conftest.py's):
where a run ends: held after it converged, at its time limit, under a supervisor."""

from __future__ import annotations

import pytest

from analysis.judge import JUDGED, judge
from analysis.run_end import HOLD_S, origin_s, the_run
from messages.goal import Goal
from messages.supervisor import SupervisorStatus
from messages.topics import (
    CONTROL_DIAGNOSTICS,
    CONTROL_GOAL,
    SUPERVISOR_STATUS,
)
from record.sessions import load_session
from tests.analysis.conftest import ROBOT, START_NS, session_of, write
from wbc import dq
from wbc.geometry import scenarios
from wbc.laws.kinematic_run import integrate
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.task import PoseTask, PositionTask


def test_a_time_limit_ends_a_run_that_did_not_converge_at_the_limit(runs):  # noqa: F811
    _, session = runs["LP"]
    early = {
        name: [m for m in messages if m.header.stamp_ns < START_NS + 2 * 10**9]
        for name, messages in session.items()
    }
    judged = judge(early, ROBOT, time_limit_s=1.0)
    assert not judged["converged"]
    last = the_run(early, 1.0)[0][CONTROL_DIAGNOSTICS.name][-1].header.stamp_ns
    assert last <= START_NS + 10**9 < last + 30_000_000


def test_a_run_that_converged_only_after_its_time_limit_is_judged_as_it_stood_at_the_limit(
    runs,  # noqa: F811
):
    """A lockstep run whose stop came late (the machine was busy) went on past its limit and
    converged there: it is judged on the same steps as a run stopped in time, not converged."""
    _, session = runs["LP"]
    origin = origin_s(session)
    converged_s = the_run(session)[0][CONTROL_DIAGNOSTICS.name][-1].header.stamp_ns / 1e9
    limit_s = converged_s - origin - 0.5
    in_time = {
        name: [m for m in messages if m.header.stamp_ns / 1e9 <= origin + limit_s]
        for name, messages in session.items()
    }
    late, stopped = judge(session, ROBOT, time_limit_s=limit_s), judge(in_time, ROBOT, limit_s)
    assert judge(session, ROBOT)["converged"]
    assert not late["converged"] and not stopped["converged"]
    assert late["commands_digest"] == stopped["commands_digest"]
    assert late["iterations"] == stopped["iterations"] < len(session[CONTROL_DIAGNOSTICS.name])


@pytest.mark.parametrize("tolerance", [5e-3, 1e-5], ids=["reached", "never-reached"])
def test_a_position_goal_passed_on_by_the_supervisor_converges_as_without_it(
    tmp_path, tolerance: float
) -> None:
    """An LP run to a position, its goal passed on by the staging supervisor (phase ``direct``,
    then ``reached`` within its pose_tolerance, the default 5e-3 or the least, which this run
    never reaches), written and read as a recording: it converged when the error went under
    0.01 in the direct phase, as it did with no supervisor (before, only pose and reached
    phases counted: it converged HOLD_S after reached, or never)."""
    position = dq.translation(ROBOT.fkm(scenarios.REACH_GOAL))[1:]
    run = integrate(
        LPLaw(ROBOT, LPParams()),
        scenarios.HOME,
        PositionTask(position),
        scenarios.DT,
        1500,
        tolerance=1e-4,
    )
    session = session_of(run, "lp", PoseTask(ROBOT.fkm(scenarios.REACH_GOAL)))
    goal = session[CONTROL_GOAL.name][0]
    session[CONTROL_GOAL.name] = [
        Goal(header=goal.header, task="position", position=tuple(position))
    ]
    unsupervised = judge(load_session(write(tmp_path / "alone.mcap", session), JUDGED), ROBOT)
    statuses = [
        SupervisorStatus(
            header=d.header.model_copy(update={"source": "supervisor"}),
            phase="direct" if d.error_norm >= tolerance else "reached",
            candidate=0,
            plans=0,
            replans=0,
            stalls=0,
            error_norm=d.error_norm,
        )
        for d in session[CONTROL_DIAGNOSTICS.name]
    ]
    supervised = {**session, SUPERVISOR_STATUS.name: statuses}
    judged = judge(load_session(write(tmp_path / "supervised.mcap", supervised), JUDGED), ROBOT)
    assert unsupervised["converged"] and judged["converged"]
    assert judged["iterations"] == unsupervised["iterations"]
    first_small = next(
        i for i, d in enumerate(session[CONTROL_DIAGNOSTICS.name]) if d.error_norm < 0.01
    )
    assert judged["iterations"] == first_small + round(HOLD_S / scenarios.DT) + 1
