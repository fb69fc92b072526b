"""The staging supervisor (wbc/planning/staging_supervisor.py): whole kinematic runs from a
plan to the goal pose, the goals it refuses, its stalls, and its phases."""

from __future__ import annotations

import math

import numpy as np

from studies.gain_sets import supervised_params
from tests.wbc.wbc_scenarios import robot
from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.geometry.scenarios import DT, HOME
from wbc.laws.kinematic_run import integrate_supervised
from wbc.laws.lp_law import LPLaw
from wbc.planar import planar_pose
from wbc.planning.staging_supervisor import Phase, StagingSupervisor, SupervisorParams
from wbc.task import PoseTask

MODEL = robot()
KINEMATIC = SupervisorParams(pose_tolerance=1e-3)
"""A kinematic run's tolerance (the measured pose's default is looser)."""
STEPS = int(60.0 / DT)


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
