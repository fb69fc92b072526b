"""analysis.judge on sessions of real kinematic runs of the LP (tests/analysis/conftest.py's):
a run judged from its messages alone, with the truth and without it."""

from __future__ import annotations

import numpy as np
import pytest

from analysis.commands import commands, effort
from analysis.judge import judge
from analysis.run_end import HOLD_S, the_run
from messages.obstacles import Circle, Plane, Solids
from messages.topics import (
    CONTROL_DIAGNOSTICS,
    ROBOT_STATE,
    SIM_TRUTH,
)
from messages.truth import SimTruth
from tests.analysis.conftest import ROBOT
from wbc.geometry import scenarios
from wbc.laws.kinematic_run import effort_of


def with_truth(session: dict[str, list], goal: np.ndarray, shift: float = 0.0) -> dict:
    """The session with a ground truth at each state: the state moved by ``shift`` in x (an
    estimator that far off), the goal and one obstacle as the simulator places them."""
    obstacle = scenarios.OBSTACLE
    truth = [
        SimTruth(
            header=s.header,
            base_pose=(s.base_pose[0] + shift, *s.base_pose[1:]),
            arm_joints=s.arm_joints,
            end_effector=s.end_effector,
            contacts=0,
            in_contact=False,
            goal=tuple(goal),
            reference_pose=(0.0, 0.0, 0.0),
            obstacles=(Circle(x=obstacle.x, y=obstacle.y, radius=obstacle.radius),),
        )
        for s in session[ROBOT_STATE.name]
    ]
    return {**session, SIM_TRUTH.name: truth}


def test_a_converged_run_ends_hold_s_after_it_converged_and_is_judged_on_the_truth(runs):  # noqa: F811
    run, session = runs["LP"]
    goal = ROBOT.fkm(scenarios.REACH_GOAL)
    judged = judge(with_truth(session, goal, shift=0.004), ROBOT)
    assert judged["converged"] and judged["truth"] == "recorded"
    cut, _ = the_run(session)
    diagnostics = cut[CONTROL_DIAGNOSTICS.name]
    since = next(d.header.stamp_ns for d in diagnostics if d.error_norm < 0.01) / 1e9
    assert diagnostics[-1].header.stamp_ns / 1e9 == pytest.approx(since + HOLD_S, abs=0.02)
    assert judged["iterations"] == len(diagnostics) < len(session[CONTROL_DIAGNOSTICS.name])
    x = np.array(cut[ROBOT_STATE.name][-1].end_effector)
    assert judged["final_error"] == pytest.approx(np.linalg.norm(x - goal), abs=1e-12)
    assert judged["estimator_error"]["position_m"] == pytest.approx(0.004, abs=1e-9)
    assert judged["contacts"] == 0 and judged["joint_limit_violations"] == 0
    centre = min(
        np.hypot(
            s.base_pose[0] + 0.004 - scenarios.OBSTACLE.x, s.base_pose[1] - scenarios.OBSTACLE.y
        )
        for s in cut[ROBOT_STATE.name]
    )
    gap = centre - scenarios.OBSTACLE.radius - ROBOT.base.body_radius
    assert judged["min_obstacle_clearance_m"] == pytest.approx(gap, abs=1e-4)
    stamps, u = commands(cut)
    inputs = np.array([out.u for out in run.outputs[: len(u)]])
    assert np.allclose(u, inputs, atol=1e-12)  # u as the law computed it
    dt = float(np.median(np.diff(stamps))) * 1e-9
    assert effort(cut)["metric1"] == effort_of(u, dt).velocity_l1


def test_a_recording_without_truth_says_so_and_judges_the_rest(runs):  # noqa: F811
    _, session = runs["LP"]
    judged = judge(session, ROBOT)
    assert judged["truth"] == "absent"
    for key in (
        "final_error",
        "contacts",
        "joint_limit_violations",
        "min_obstacle_clearance_m",
        "arm_penetrations",
        "arm_clearance_m",
    ):
        assert judged[key] is None, key
    assert judged["estimator_error"]["samples"] == 0
    assert judged["converged"] and judged["final_error_estimated"] < 0.01
    assert judged["effort"] is not None and judged["iterations"] > 0


def test_the_arms_clearance_and_penetrations_are_judged_from_the_truth(runs):  # noqa: F811
    """A solid in the truth: the judge reports the simulator's count and each part's least
    clearance over the run, from the true configurations; a table top cut at the arm's least
    height has the wrist or the hand at a negative clearance."""
    _, session = runs["LP"]
    truth = with_truth(session, ROBOT.fkm(scenarios.REACH_GOAL))[SIM_TRUTH.name]
    heights = [
        ROBOT.link_points(np.array([*t.base_pose, *t.arm_joints]))[3:, 2].min() for t in truth
    ]
    table = Plane(
        name="table",
        normal=(0.0, 0.0, 1.0),
        offset=float(min(heights)) + 0.01,
        footprint=((-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0)),
    )
    solids = Solids(planes=(table,))
    marked = [t.model_copy(update={"solids": solids, "arm_penetrations": 3}) for t in truth]
    judged = judge({**session, SIM_TRUTH.name: marked}, ROBOT)
    assert judged["arm_penetrations"] == 3
    least = judged["arm_clearance_m"]
    assert set(least) == set(ROBOT.collision.names)
    assert min(least.values()) < -0.01
    assert judge({**session, SIM_TRUTH.name: truth}, ROBOT)["arm_clearance_m"] is None
