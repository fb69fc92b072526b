"""Closed-loop behaviour of the laws under kinematic integration q += u dt (chapters 5, 6)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from studies.gain_sets import BORDER_PARAMS, LP_PARAMS, OBSTACLE_PARAMS
from tests.wbc.wbc_scenarios import integrate, pose_task, position_task, robot
from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.geometry.scenarios import (
    DT,
    HOME,
    JOINT_LIMIT_GOAL,
    OBSTACLE,
    OBSTACLE_GOAL,
    STARTS_AND_GOALS,
)
from wbc.laws.cascade_law import CascadeLaw
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.pinv_law import PseudoinverseLaw
from wbc.task import PoseTask, PositionTask

MODEL = robot()
POSE_PARAMS, POSITION_PARAMS = LP_PARAMS["pose"], LP_PARAMS["position"]


def nonholonomic_residual(q: np.ndarray, u: np.ndarray) -> float:
    """|x' sin(phi) - y' cos(phi)| (5.11)."""
    return abs(u[0] * np.sin(q[2]) - u[1] * np.cos(q[2]))


SECONDARY_ROWS = 2
"""The default LP's two secondary residual rows (waist centring, base target): task rows too."""


def check_lp_outputs(run, task_dof: int) -> None:
    """Every LP output: 5.11 to 1e-9, inside the bounds, parsimonious (5.30)."""
    arm_min, arm_max = MODEL.q_min[3:], MODEL.q_max[3:]
    for q, out in zip(run.configurations, run.outputs, strict=True):
        assert out.status == "optimal"
        assert nonholonomic_residual(q, out.u) <= 1e-9
        assert np.all(np.abs(out.u) <= MODEL.velocity_max + 1e-9)
        assert np.all(q[3:] >= arm_min) and np.all(q[3:] <= arm_max)
        others = [name for name in out.active_constraints if "bound" not in name]
        bound = task_dof + SECONDARY_ROWS + 1 + len(others)
        assert out.nonzero <= bound, (out.nonzero, out.active_constraints)


@pytest.mark.parametrize("start, goal", STARTS_AND_GOALS)
def test_lp_law_reaches_pose_goals_within_every_constraint(start, goal):
    task = pose_task(MODEL, goal)
    run = integrate(LPLaw(MODEL, POSE_PARAMS), start, task, steps=3000)
    assert run.final_error < 1e-3
    check_lp_outputs(run, task.dof)


@pytest.mark.parametrize("start, goal", STARTS_AND_GOALS)
def test_lp_law_reaches_position_goals_with_few_joints(start, goal):
    task = position_task(MODEL, goal)
    run = integrate(LPLaw(MODEL, POSITION_PARAMS), start, task, steps=3000)
    assert run.final_error < 1e-3
    check_lp_outputs(run, task.dof)
    # More redundancy, more parsimony (fig. 6.12): the LP leaves joints idle most steps.
    assert np.median([out.nonzero for out in run.outputs]) < MODEL.dof


@pytest.mark.parametrize("start, goal", STARTS_AND_GOALS)
@pytest.mark.parametrize("make_task", [pose_task, position_task])
def test_cascade_law_reaches_goals_and_obeys_the_nonholonomic_constraint(start, goal, make_task):
    run = integrate(CascadeLaw(MODEL), start, make_task(MODEL, goal), steps=3000)
    assert run.final_error < 1e-3
    for q, out in zip(run.configurations, run.outputs, strict=True):
        assert nonholonomic_residual(q, out.u) <= 1e-9


def test_pseudoinverse_law_uses_every_joint_where_the_lp_law_does_not():
    """5.29 itself (no secondary term) against the classic law on a position task."""
    start, goal = STARTS_AND_GOALS[0]
    task = position_task(MODEL, goal)
    pinv = integrate(PseudoinverseLaw(MODEL), start, task, steps=3000)
    params = LPParams(eta=1.0, beta=10.0, waist_centring=0.0, base_target=0.0)
    lp = integrate(LPLaw(MODEL, params), start, task, steps=3000)
    assert pinv.final_error < 1e-3
    assert all(out.nonzero == MODEL.dof for out in pinv.outputs)
    assert max(out.nonzero for out in lp.outputs[5:]) < MODEL.dof


def test_joint_limit_kept_by_lp_law_and_passed_by_pseudoinverse_law():
    """Figure 6.10: a goal whose nearest arm pose puts the elbow q3 beyond its limit."""
    task = pose_task(MODEL, JOINT_LIMIT_GOAL)
    elbow = 5
    pinv = integrate(PseudoinverseLaw(MODEL), HOME, task, steps=2000)
    lp = integrate(LPLaw(MODEL, POSE_PARAMS), HOME, task, steps=2000)
    assert max(q[elbow] for q in pinv.configurations) > MODEL.q_max[elbow]
    assert max(q[elbow] for q in lp.configurations) <= 0.9 * MODEL.q_max[elbow] + 1e-9


def base_clearance(run) -> np.ndarray:
    """Distance between the base's rim and the obstacle's edge at every step (m)."""
    centres = np.array(run.configurations)[:, :2]
    distance = np.hypot(centres[:, 0] - OBSTACLE.x, centres[:, 1] - OBSTACLE.y)
    return distance - OBSTACLE.radius - MODEL.base.body_radius


def test_obstacle_lies_on_the_free_path():
    free = integrate(LPLaw(MODEL), HOME, pose_task(MODEL, OBSTACLE_GOAL), 3000)
    assert free.final_error < 1e-3
    assert base_clearance(free).min() < 0.0


@pytest.mark.parametrize(
    ("params", "constraint"),
    [(OBSTACLE_PARAMS, "obstacle_vector_field"), (BORDER_PARAMS, "obstacle_border")],
)
def test_an_obstacle_constraint_goes_round_the_obstacle_to_the_goal(params, constraint):
    law = LPLaw(MODEL, params)
    run = integrate(law, HOME, pose_task(MODEL, OBSTACLE_GOAL), 4000, obstacles=[OBSTACLE])
    assert base_clearance(run).min() > 0.0
    assert any(constraint in out.active_constraints for out in run.outputs)
    assert run.final_error < 1e-3


def test_the_default_obstacle_constraint_lets_the_base_near_no_faster_than_its_bound():
    """The vector-field inequality, the default obstacle constraint, in the closed loop of
    6.2.3: at every step the distance d of the base's point from the obstacle's grown circle
    changes by (d_{k+1} - d_k) / dt >= -eta_d d_k (a finite difference along the step taken),
    so d stays positive; every program is solved, and the run converges."""
    params = OBSTACLE_PARAMS
    run = integrate(
        LPLaw(MODEL, params), HOME, pose_task(MODEL, OBSTACLE_GOAL), 4000, obstacles=[OBSTACLE]
    )
    q = np.array(run.configurations)
    ahead = params.obstacle_lookahead
    points = q[:, :2] + ahead * np.column_stack((np.cos(q[:, 2]), np.sin(q[:, 2])))
    grown = OBSTACLE.radius + MODEL.base.body_radius + params.obstacle_margin + ahead
    d = np.hypot(points[:, 0] - OBSTACLE.x, points[:, 1] - OBSTACLE.y) - grown
    slack = np.diff(d) / DT + params.obstacle_gain * d[:-1]
    assert slack.min() >= -1e-9
    assert slack.min() < 1e-3  # the bound was reached: the inequality held the base
    assert d.min() > 0.0
    assert any("obstacle_vector_field" in out.active_constraints for out in run.outputs)
    assert all(out.ok for out in run.outputs) and run.final_error < 1e-3


def test_conservative_constraint_stops_the_base_before_the_obstacle():
    law = LPLaw(MODEL, LPParams(obstacle_mode="conservative"))
    run = integrate(law, HOME, pose_task(MODEL, OBSTACLE_GOAL), 3000, obstacles=[OBSTACLE])
    assert base_clearance(run).min() > 0.0
    assert run.final_error > 0.1
    assert np.hypot(*run.outputs[-1].u[:2]) < 1e-3


def test_error_derivative_bound_stops_joints_when_the_end_effector_stalls():
    """A position out of reach (1.3 m high): the end effector stalls short of it (5.9, 5.10)."""
    unreachable = PositionTask(np.array([0.5, 0.0, 1.3]))

    def last_second_speed(bound: str) -> float:
        params = LPParams(eta=1.0, beta=10.0, error_bound=bound, velocity_cost=0.0)
        run = integrate(LPLaw(MODEL, params), HOME, unreachable, steps=1500)
        assert run.final_error > 0.3
        steps = int(1.0 / DT)
        return float(np.mean([np.abs(out.u).sum() for out in run.outputs[-steps:]]))

    assert last_second_speed("derivative") < 1e-6
    assert last_second_speed("error") > 0.1


SADDLE = np.array([-0.9022, -0.572, -0.0045, 0.0, 0.36, -0.8683, -0.0528, -0.4009])
"""Where seed 1 of the simulated obstacle experiment stalled: the base's point on the border
of the obstacle, facing its centre, the goal straight behind it (error 0.65 for 60 s)."""
SADDLE_OBSTACLE = Circle(-0.3888, -0.6056, 0.1)
SADDLE_GOAL = dq.normalize(
    np.array([0.945648, 0.023547, -0.251532, -0.204763, -0.076033, 0.509034, -0.351501, 0.139184])
)


def test_a_base_stalled_on_the_borders_saddle_goes_round_and_reaches_the_goal():
    task = PoseTask(SADDLE_GOAL)
    for params in (BORDER_PARAMS, OBSTACLE_PARAMS):
        stuck = LPLaw(MODEL, dataclasses.replace(params, obstacle_circulation=0.0))
        run = integrate(stuck, SADDLE, task, 1000, obstacles=[SADDLE_OBSTACLE])
        assert run.final_error > 0.5  # the saddle holds without the circulation term
    law = LPLaw(MODEL, OBSTACLE_PARAMS)
    run = integrate(law, SADDLE, task, 3000, obstacles=[SADDLE_OBSTACLE])
    assert run.converged
    q = np.array(run.configurations)
    gap = np.hypot(q[:, 0] - SADDLE_OBSTACLE.x, q[:, 1] - SADDLE_OBSTACLE.y)
    assert gap.min() > SADDLE_OBSTACLE.radius + MODEL.base.body_radius
    assert all(out.ok for out in run.outputs)
