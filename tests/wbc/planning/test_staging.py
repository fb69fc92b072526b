"""The staging supervisor's parts: drive tasks, conditioning, candidates, and whole runs."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from studies.gain_sets import supervised_params
from studies.goal_sets import FAMILIES, goals
from tests.wbc.planning.crowd import CHECK_GAP_S, crowd
from tests.wbc.wbc_scenarios import robot
from wbc import dq
from wbc.conditioning import smallest_singular_value
from wbc.geometry.obstacles import Circle
from wbc.geometry.scenarios import DT, HOME, REACH_GOAL
from wbc.laws.kinematic_run import integrate, integrate_supervised
from wbc.laws.lp_law import LPLaw
from wbc.planar import planar_pose
from wbc.planning.drive_tasks import HeadingTask, PointTask, offset_point
from wbc.planning.staging import StagingParams, arm_box, plan
from wbc.planning.staging_supervisor import Phase, StagingSupervisor, SupervisorParams
from wbc.task import PoseTask

MODEL = robot()
KINEMATIC = SupervisorParams(pose_tolerance=1e-3)
"""A kinematic run's tolerance (the measured pose's default is looser)."""
STEPS = int(60.0 / DT)


def finite_difference(task, q: np.ndarray, step: float = 1e-6) -> np.ndarray:
    pose, jacobian = MODEL.kinematics(q)
    columns = []
    for i in range(q.size):
        dq_ = np.zeros_like(q)
        dq_[i] = step
        plus = task.error(*MODEL.kinematics(q + dq_), q + dq_)[0]
        minus = task.error(*MODEL.kinematics(q - dq_), q - dq_)[0]
        columns.append((plus - minus) / (2 * step))
    return np.column_stack(columns)


@pytest.mark.parametrize(
    "task",
    [
        PointTask(np.array([0.4, -0.2]), np.array([0.1, -0.3, 0.2, 0.0, 0.4])),
        HeadingTask(2.0, np.array([0.1, -0.3, 0.2, 0.0, 0.4]), np.array([0.0, 0.0])),
    ],
)
def test_drive_task_jacobians_are_the_derivatives_of_their_errors(task) -> None:
    q = np.array([0.3, -0.1, 0.7, 0.2, -0.4, 0.1, 0.3, -0.2])
    _, jacobian = task.error(*MODEL.kinematics(q), q)
    np.testing.assert_allclose(jacobian, finite_difference(task, q), atol=1e-8)


def test_a_point_task_drives_the_point_ahead_of_the_axle_and_the_arm_there() -> None:
    task = PointTask(np.array([-0.5, 0.6]), np.array([0.2, -0.5, 0.1, 0.3, 0.2]))
    run = integrate(LPLaw(MODEL), HOME, task, DT, STEPS, tolerance=1e-3)
    q = run.configurations[-1]
    assert run.converged
    np.testing.assert_allclose(offset_point(q, task.lookahead), task.point, atol=2e-3)
    np.testing.assert_allclose(q[3:], task.arm, atol=2e-3)
    for q_k, out in zip(run.configurations, run.outputs, strict=True):
        assert out.status == "optimal"
        assert abs(out.u[0] * math.sin(q_k[2]) - out.u[1] * math.cos(q_k[2])) < 1e-9


def test_a_heading_task_turns_the_base_in_place() -> None:
    task = HeadingTask(-2.5, HOME[3:], HOME[:2])
    run = integrate(LPLaw(MODEL), HOME, task, DT, STEPS, tolerance=1e-3)
    q = run.configurations[-1]
    assert run.converged
    assert abs(q[2] - -2.5) < 2e-3
    assert np.hypot(*q[:2]) < 1e-9


def test_conditioning_vanishes_where_the_arm_loses_a_direction() -> None:
    # The wrist rolled a quarter turn puts the wrist pitch axis parallel to the shoulder's and
    # the elbow's: the three then move the gripper in the arm's plane, as the base's forward
    # motion does, and nothing turns it about the vertical without swinging it sideways.
    rolled = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, math.pi / 2, 0.0])
    assert smallest_singular_value(MODEL, rolled) < 1e-9
    assert smallest_singular_value(MODEL, HOME) > 0.01


def test_every_candidate_reaches_the_goal_pose_inside_the_shrunk_joint_box() -> None:
    params = StagingParams()
    low, high = arm_box(MODEL, params.safety_factor, params.joint_margins[-1])
    for start, goal in goals(FAMILIES["anywhere"], 5, MODEL, seed=7):
        found = plan(MODEL, start, MODEL.fkm(goal), params=params).candidates
        assert found
        assert [c.score for c in found] == sorted(c.score for c in found)
        for c in found:
            x = MODEL.fkm(c.q)
            np.testing.assert_allclose(x, dq.nearest_equivalent(MODEL.fkm(goal), x), atol=1e-5)
            assert c.q[3] == 0.0
            assert np.all(c.q[4:] >= low[1:] - 1e-9) and np.all(c.q[4:] <= high[1:] + 1e-9)


def test_candidates_keep_the_base_clear_of_obstacles() -> None:
    start, goal = goals(FAMILIES["anywhere"], 1, MODEL, seed=3)[0]
    free = plan(MODEL, start, MODEL.fkm(goal)).candidates
    blocker = Circle(*free[0].base[:2], 0.1)
    found = plan(MODEL, start, MODEL.fkm(goal), [blocker]).candidates
    clearance = blocker.radius + MODEL.base.body_radius
    assert all(math.hypot(*(c.base[:2] - free[0].base[:2])) >= clearance for c in found)


def test_a_goal_behind_the_robot_is_reached_through_lp_steps_within_the_limits() -> None:
    goal = MODEL.fkm(np.array([-0.7, 0.3, math.pi - 0.4, 0.2, -0.3, -0.4, 0.2, 0.3]))
    supervisor = StagingSupervisor(MODEL, goal, params=KINEMATIC)
    run = integrate_supervised(LPLaw(MODEL), supervisor, HOME, DT, STEPS)
    assert run.converged and supervisor.phase is Phase.REACHED
    assert [e.detail for e in supervisor.events if e.kind == "phase"][-1] == "pose"
    assert supervisor.way() == ()  # the base stands at its candidate
    q = np.array(run.configurations)
    assert np.all(q >= MODEL.q_min - 1e-9) and np.all(q <= MODEL.q_max + 1e-9)
    u = run.velocities()
    assert np.all(np.abs(u) <= MODEL.velocity_max + 1e-9)
    assert all(out.status == "optimal" for out in run.outputs)
    x = MODEL.fkm(run.configurations[-1])
    assert np.linalg.norm(x - dq.nearest_equivalent(goal, x)) < KINEMATIC.pose_tolerance


def test_a_goal_no_configuration_reaches_is_reported_at_once_and_gives_no_task() -> None:
    floating = planar_pose(0.5, 0.0, 0.0, 2.0)
    supervisor = StagingSupervisor(MODEL, floating)
    assert supervisor.step(HOME, 0.0) is None
    assert supervisor.phase is Phase.UNREACHABLE
    assert "no whole-body configuration" in supervisor.reason


def test_a_walled_off_goal_is_reported_at_once_with_no_way_and_the_robot_never_moves() -> None:
    goal_q = np.array([2.0, 0.0, 0.0, 0.0, -0.3, -0.4, 0.2, 0.3])
    goal = MODEL.fkm(goal_q)
    # A ring of posts 0.9 m round the goal, too close together for the base to pass.
    ring = [
        Circle(2.0 + 0.9 * math.cos(a), 0.9 * math.sin(a), 0.08)
        for a in np.linspace(0.0, 2.0 * math.pi, 30, endpoint=False)
    ]
    supervisor = StagingSupervisor(MODEL, goal, ring)
    run = integrate_supervised(LPLaw(MODEL), supervisor, HOME, DT, STEPS, ring)
    assert supervisor.phase is Phase.UNREACHABLE and not run.converged and not run.outputs
    assert "have no way to their staging point" in supervisor.reason, supervisor.reason
    assert "no way round the obstacles from (0.00, 0.00)" in supervisor.reason


def test_stalls_are_re_planned_a_bounded_number_of_times_and_then_the_robot_stops() -> None:
    goal = MODEL.fkm(np.array([-0.7, 0.3, math.pi - 0.4, 0.2, -0.3, -0.4, 0.2, 0.3]))
    # Every phase must shed 90 % of its error in 0.1 s: none does, so each one stalls.
    hasty = SupervisorParams(stall_window_s=0.1, stall_reduction=0.9)
    supervisor = StagingSupervisor(MODEL, goal, params=hasty)
    run = integrate_supervised(LPLaw(MODEL), supervisor, HOME, DT, STEPS)
    assert supervisor.phase is Phase.UNREACHABLE and not run.converged
    assert supervisor.replans == hasty.max_replans
    assert supervisor.reason.startswith("stalled in") or "was tried" in supervisor.reason
    assert sum(e.kind == "stall" for e in supervisor.events) == supervisor.replans + 1
    assert len(run.outputs) < STEPS


def test_the_supervisor_drives_round_a_circle_on_the_straight_way_without_contact() -> None:
    """The goal's base 1.4 m ahead, a post of 0.1 m half way: the base drives the planned way
    round it, every command one LP step with the obstacle constraint on, and the base's body
    never comes within the LP's margin of the post."""
    goal = MODEL.fkm(np.array([1.4, 0.0, 0.0, 0.0, -0.3, -0.4, 0.2, 0.3]))
    post = Circle(0.7, 0.02, 0.1)
    law = LPLaw(MODEL, supervised_params())
    supervisor = StagingSupervisor(MODEL, goal, [post], params=KINEMATIC)
    run = integrate_supervised(law, supervisor, HOME, DT, STEPS, [post])
    assert run.converged and supervisor.phase is Phase.REACHED, supervisor.events
    way = supervisor.tried[0].way
    assert way is not None and way.arcs and len(way.waypoints) >= 2
    legs = [e.detail for e in supervisor.events if e.detail.startswith("drive, leg")]
    assert len(legs) >= 2
    q = np.array(run.configurations)
    gap = np.hypot(q[:, 0] - post.x, q[:, 1] - post.y) - post.radius - MODEL.base.body_radius
    assert gap.min() > 0.0
    assert all(out.status == "optimal" for out in run.outputs)
    x = MODEL.fkm(run.configurations[-1])
    assert np.linalg.norm(x - dq.nearest_equivalent(goal, x)) < KINEMATIC.pose_tolerance


def test_the_pose_task_alone_is_what_runs_once_the_base_stands_at_its_candidate() -> None:
    goal = MODEL.fkm(np.array([0.6, 0.1, 0.2, 0.0, -0.3, -0.4, 0.2, 0.3]))
    supervisor = StagingSupervisor(MODEL, goal)
    first = supervisor.step(HOME, 0.0)
    assert supervisor.candidate is not None
    at_candidate = supervisor.candidate.q
    supervisor = StagingSupervisor(MODEL, goal)
    task = supervisor.step(at_candidate, 0.0)
    assert isinstance(task, PoseTask) and supervisor.phase in (Phase.POSE, Phase.REACHED)
    assert not isinstance(first, PoseTask)


def test_a_goal_inside_an_obstacle_or_too_far_is_refused_before_any_search() -> None:
    goal = MODEL.fkm(np.array([0.6, 0.1, 0.2, 0.0, -0.3, -0.4, 0.2, 0.3]))
    x, y = dq.translation(goal)[1:3]
    inside = plan(MODEL, HOME, goal, [Circle(x + 0.05, y, 0.1)])
    assert not inside.candidates and "lies inside obstacle 1" in inside.reason
    far = plan(MODEL, HOME, planar_pose(100.0, 0.0, 0.0, 0.3))
    assert not far.candidates and "farther than the 10 m" in far.reason


def test_a_search_stops_at_its_cpu_budget_and_says_so() -> None:
    goal = MODEL.fkm(np.array([0.6, 0.1, 0.2, 0.0, -0.3, -0.4, 0.2, 0.3]))
    spent = plan(MODEL, HOME, goal, params=StagingParams(budget_s=0.0))
    assert not spent.candidates and "planning budget" in spent.reason


def test_a_plan_round_the_most_circles_a_message_holds_keeps_to_its_cpu_budget() -> None:
    """256 circles: building the way's graph alone took 3.3-4.8 s of CPU past a budget of 2,
    and the plan 6.1 s here. The budget now holds for the whole plan, graph included, and the
    reason says it ran out."""
    goal = MODEL.fkm(REACH_GOAL)
    x, y = dq.translation(goal)[1:3]
    circles = [Circle(*c) for c in crowd(((HOME[0], HOME[1]), (x, y)))]
    params = StagingParams(budget_s=0.3)
    started = time.thread_time()
    spent = plan(MODEL, HOME, goal, circles, params)
    cpu_s = time.thread_time() - started
    assert cpu_s <= params.budget_s + CHECK_GAP_S, cpu_s
    assert not spent.candidates and "planning budget of 0.3 s" in spent.reason, spent.reason


def test_candidates_whose_base_would_leave_the_region_are_left_out_and_named_so() -> None:
    """The region is the floor the camera sees: a base driven out of it loses its fixes (in
    a soak the state went invalid so and stayed). Every candidate kept stands, stages and
    drives inside it; with none inside, the reason says so."""
    goal = MODEL.fkm(np.array([0.6, 0.1, 0.2, 0.0, -0.3, -0.4, 0.2, 0.3]))
    best = plan(MODEL, HOME, goal).candidates[0]
    region = ((0.0, 1.0, float(best.base[1]) - 0.005),)  # y <= just under the best's
    kept = plan(MODEL, HOME, goal, params=StagingParams(region=region))
    assert kept.candidates and not kept.reason
    for c in kept.candidates:
        points = [c.base, c.staging, *(c.way.waypoints if c.way else ())]
        assert all(p[1] <= region[0][2] for p in points), points
    nowhere = plan(MODEL, HOME, goal, params=StagingParams(region=((1.0, 0.0, -0.5),)))
    assert not nowhere.candidates
    assert "take the base where the camera cannot see it" in nowhere.reason, nowhere.reason


def test_candidates_all_blocked_by_obstacles_are_named_as_such() -> None:
    goal_q = np.array([2.0, 0.0, 0.0, 0.0, -0.3, -0.4, 0.2, 0.3])
    goal = MODEL.fkm(goal_q)
    x, y = dq.translation(goal)[1:3]
    # A wide disc round the goal, the gripper's own spot left out: no base can stand near it.
    ring = [
        Circle(x + 0.6 * math.cos(a), y + 0.6 * math.sin(a), 0.45)
        for a in np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False)
    ]
    blocked = plan(MODEL, HOME, goal, ring)
    assert not blocked.candidates and "of an obstacle" in blocked.reason, blocked.reason


def test_a_supervisor_waits_for_its_plan_and_holds_meanwhile() -> None:
    goal = MODEL.fkm(np.array([0.6, 0.1, 0.2, 0.0, -0.3, -0.4, 0.2, 0.3]))
    supervisor = StagingSupervisor(MODEL, goal)
    assert supervisor.update(HOME, 0.0) is None and supervisor.phase is Phase.PLANNING
    request = supervisor.pending
    assert request is not None and supervisor.update(HOME, 0.02) is None
    assert supervisor.pending is request  # one plan asked for, not one per step
    supervisor.take(request.run(), 0.04)
    assert supervisor.pending is None and supervisor.phase is not Phase.PLANNING
    assert supervisor.update(HOME, 0.06) is not None


def test_the_way_is_the_planned_waypoints_then_the_candidates_base() -> None:
    """What the view draws of the plan: round an obstacle on the straight way, the drive's
    waypoints (each outside the obstacle's grown disc), the staging point, the base."""
    goal = MODEL.fkm(np.array([-0.7, 0.3, math.pi - 0.4, 0.2, -0.3, -0.4, 0.2, 0.3]))
    obstacle = Circle(-0.35, 0.15, 0.1)
    supervisor = StagingSupervisor(MODEL, goal, (obstacle,))
    assert supervisor.way() == ()  # no candidate yet
    supervisor.step(HOME, 0.0)
    assert supervisor.phase is Phase.DRIVE
    candidate = supervisor.candidate
    *waypoints, staging, base = supervisor.way()
    assert np.allclose(staging, candidate.staging) and np.allclose(base, candidate.base[:2])
    ahead = candidate.way.waypoints[supervisor.leg : -1]  # the legs not yet driven
    assert waypoints and [tuple(p) for p in waypoints] == [tuple(p) for p in ahead]
    grown = obstacle.radius + MODEL.base.body_radius + supervisor.staging.clearance
    assert all(math.hypot(p[0] - obstacle.x, p[1] - obstacle.y) >= grown for p in waypoints)
