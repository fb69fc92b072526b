"""analysis.judge on sessions of real kinematic runs of the LP (tests/analysis/conftest.py's):
a run judged from its messages alone, with the truth and without it, and under a supervisor
from the file a recorder writes."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from analysis.judge import HOLD_S, JUDGED, commands, commands_csv, effort, judge, origin_s, the_run
from messages.goal import Goal
from messages.obstacles import Circle, Plane, Solids
from messages.supervisor import SupervisorStatus
from messages.topics import (
    CONTROL_DIAGNOSTICS,
    CONTROL_GOAL,
    ROBOT_STATE,
    SIM_TRUTH,
    SUPERVISOR_STATUS,
)
from messages.truth import SimTruth
from profiles.deploy_files import ROBOT_FILE
from record.sessions import load_session
from tests.analysis.conftest import ROBOT, START_NS, session_of, write
from wbc import dq
from wbc.geometry import scenarios
from wbc.laws.kinematic_run import effort_of, integrate
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.robot import MobileManipulator
from wbc.task import PoseTask, PositionTask


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


def test_the_commands_csv_has_a_column_per_joint_of_the_robots_arm(runs, tmp_path):
    _, session = runs["LP"]
    lines = commands_csv(session, ROBOT).splitlines()
    joints = [f"q{i}_dot" for i in range(1, ROBOT.arm_dof + 1)]
    assert lines[0].split(",") == ["stamp_s", "forward", "angular", *joints]
    assert {len(line.split(",")) for line in lines[1:]} == {len(lines[0].split(","))}
    description = yaml.safe_load(ROBOT_FILE.read_text())
    arm = description["arm"]
    arm["dh"] = {key: values[:4] for key, values in arm["dh"].items()}
    for key in ("joint_min", "joint_max", "velocity_max"):
        arm[key] = arm[key][:4]
    del description["collision"]
    (tmp_path / "four_joints.yaml").write_text(yaml.safe_dump(description))
    four = MobileManipulator.from_yaml(tmp_path / "four_joints.yaml")
    header = commands_csv(session, four).splitlines()[0].split(",")
    assert header[3:] == ["q1_dot", "q2_dot", "q3_dot", "q4_dot"]
