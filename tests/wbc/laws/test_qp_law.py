"""The QP law (wbc.laws.qp_law): the closed form where no row binds, the LP's rows held, the goal
of section 6.2.1 reached in a kinematic loop, and a failure reported as zero velocity."""

from __future__ import annotations

import math

import numpy as np

from tests.wbc.wbc_scenarios import pose_task, robot
from wbc.geometry.obstacles import Circle
from wbc.geometry.scenarios import DT, HOME, REACH_GOAL, STARTS_AND_GOALS
from wbc.laws.kinematic_run import integrate
from wbc.laws.qp_law import QPLaw, QPParams
from wbc.task import PoseTask

MODEL = robot()
FREE = dict(nonholonomic=False, beta=1e3, obstacle_mode="off", base_target=0.0, joint_gain=1e4)
"""No row that binds near HOME: the base holonomic, the error bound and the joints far away."""


def test_where_no_row_binds_u_is_the_damped_least_squares_closed_form() -> None:
    """u = -(J'J + lambda I)^-1 J' eta e, the minimiser of ||J u + eta e||^2 + lambda ||u||^2."""
    params = QPParams(**FREE, eta=0.05, damping=1e-2)  # a small step: no speed bound binds
    task = pose_task(MODEL, STARTS_AND_GOALS[0][1])
    q = HOME.copy()
    output = QPLaw(MODEL, params).step(q, task, DT)
    pose, jacobian = MODEL.kinematics(q)
    error, task_jacobian = task.error(pose, jacobian, q)
    closed = -np.linalg.solve(
        task_jacobian.T @ task_jacobian + params.damping * np.eye(8),
        task_jacobian.T @ (params.eta * error),
    )
    assert output.status == "optimal"
    assert np.all(np.abs(output.u) < 0.5 * MODEL.velocity_max)
    assert np.allclose(output.u, closed, atol=1e-7), (output.u, closed)


def test_the_rows_of_the_lp_hold_the_nonholonomic_equality_and_the_speed_limits() -> None:
    law = QPLaw(MODEL, QPParams(eta=50.0))  # a large gain, so the speed limits bind
    task = pose_task(MODEL, STARTS_AND_GOALS[0][1])
    q = HOME.copy()
    q[2] = 0.4
    u = law.step(q, task, DT).u
    assert abs(u[1] * math.cos(q[2]) - u[0] * math.sin(q[2])) < 1e-7  # no sideways speed
    assert np.all(np.abs(u) <= MODEL.velocity_max + 1e-9)
    assert np.isclose(np.abs(u), MODEL.velocity_max, atol=1e-6).any()


def test_the_qp_reaches_the_pose_goal_of_6_2_1_inside_the_joint_limits() -> None:
    task = PoseTask(MODEL.fkm(REACH_GOAL))
    run = integrate(QPLaw(MODEL), HOME, task, DT, 3000)
    assert run.converged and all(o.status == "optimal" for o in run.outputs)
    arm = np.array(run.configurations)[:, 3:]
    assert np.all(arm >= MODEL.q_min[3:] - 1e-9) and np.all(arm <= MODEL.q_max[3:] + 1e-9)
    # Not parsimonious: a QP spreads u over every joint it can.
    assert np.median([o.nonzero for o in run.outputs]) == 8


def test_an_infeasible_program_gives_zero_velocity_and_the_status() -> None:
    """At the goal (e = 0) the bound 5.7 forces u = 0, while the engaged border constraint 5.28
    demands an outward velocity: no u satisfies both (the LP's own test, on the QP)."""
    at_goal = PoseTask(MODEL.fkm(HOME))
    obstacle = Circle(0.3, 0.0, 0.1)  # the base is inside its extended disc
    params = QPParams(error_bound="error", obstacle_mode="border")
    output = QPLaw(MODEL, params).step(HOME, at_goal, DT, [obstacle])
    assert output.status == "infeasible"
    assert not output.u.any() and output.nonzero == 0


def test_a_program_whose_numbers_overflow_is_never_optimal() -> None:
    """At a base pose of (1e300, -1e300, 1e300) the program's costs overflow: DAQP's u was all
    NaN with the status "optimal". A u that is not finite is reported as such, as zero."""
    q = HOME.copy()
    q[:3] = (1e300, -1e300, 1e300)
    with np.errstate(over="ignore", invalid="ignore"):  # e's norm overflows, as it should
        output = QPLaw(MODEL).step(q, PoseTask(MODEL.fkm(REACH_GOAL)), DT)
    assert output.status == "non-finite"
    assert not output.u.any() and output.nonzero == 0
