"""The LP law's contract: inputs checked, failures reported as zero velocity, gains validated."""

from __future__ import annotations

import numpy as np
import pytest

from tests.wbc.wbc_scenarios import pose_task, robot
from wbc.geometry.obstacles import Circle
from wbc.geometry.scenarios import DT, HOME, STARTS_AND_GOALS
from wbc.laws.lp_law import LPLaw, LPParams, error_rate
from wbc.task import PoseTask
from wbc.validation import NonFiniteInputError

MODEL = robot()


def test_nan_configuration_is_rejected_before_any_solve():
    law = LPLaw(MODEL)
    q = HOME.copy()
    q[4] = np.nan
    with pytest.raises(NonFiniteInputError, match="configuration q"):
        law.step(q, pose_task(MODEL, STARTS_AND_GOALS[0][1]), DT)


def test_nan_obstacle_and_non_positive_dt_are_rejected():
    law = LPLaw(MODEL)
    task = pose_task(MODEL, STARTS_AND_GOALS[0][1])
    with pytest.raises(NonFiniteInputError, match="obstacle 0"):
        law.step(HOME, task, DT, [Circle(np.inf, 0.0, 0.1)])
    with pytest.raises(ValueError, match="dt"):
        law.step(HOME, task, 0.0)


def test_an_infeasible_program_gives_zero_velocity_and_the_status():
    """At the goal (e = 0) the original bound 5.7 forces u = 0, while the engaged border
    constraint 5.28 demands an outward velocity: no u satisfies both."""
    at_goal = PoseTask(MODEL.fkm(HOME))
    obstacle = Circle(0.3, 0.0, 0.1)  # the base is inside its extended disc
    law = LPLaw(MODEL, LPParams(error_bound="error", obstacle_mode="border"))
    out = law.step(HOME, at_goal, DT, [obstacle])
    assert out.status == "infeasible"
    assert np.array_equal(out.u, np.zeros(MODEL.dof))
    assert out.nonzero == 0


def test_the_default_obstacle_constraint_keeps_standing_still_feasible():
    """Where 5.28 leaves no feasible u (above), the default law's obstacle row, the
    vector-field inequality, is an inequality that u = 0 meets: the program is solved and the
    robot, at its goal, stands still."""
    at_goal = PoseTask(MODEL.fkm(HOME))
    obstacle = Circle(0.3, 0.0, 0.1)
    out = LPLaw(MODEL, LPParams(error_bound="error")).step(HOME, at_goal, DT, [obstacle])
    assert out.status == "optimal" and "obstacle_vector_field" in out.active_constraints
    assert np.array_equal(out.u, np.zeros(MODEL.dof))


def test_error_derivative_is_measured_between_steps_of_the_same_task():
    """Holding q still makes e' = 0 from the second step on, so 5.10 forces u = 0."""
    law = LPLaw(MODEL)
    task = pose_task(MODEL, STARTS_AND_GOALS[0][1])
    first = law.step(HOME, task, DT)
    second = law.step(HOME, task, DT)
    assert np.abs(first.u).sum() > 0.0
    assert np.abs(second.u).sum() == pytest.approx(0.0, abs=1e-12)
    law.reset()
    assert np.abs(law.step(HOME, task, DT).u).sum() > 0.0


def test_output_u_is_read_only():
    out = LPLaw(MODEL).step(HOME, pose_task(MODEL, STARTS_AND_GOALS[0][1]), DT)
    with pytest.raises(ValueError):
        out.u[0] = 1.0


@pytest.mark.parametrize(
    "field, value",
    [
        ("eta", 0.0),
        ("beta", -1.0),
        ("safety_factor", 1.5),
        ("joint_gain", np.nan),
        ("velocity_cost", -1e-3),
        ("error_bound", "sometimes"),
        ("obstacle_mode", "around"),
    ],
)
def test_invalid_gains_name_the_field(field, value):
    with pytest.raises(ValueError, match=f"LPParams.{field}"):
        LPParams(**{field: value})


def test_cascade_reference_does_not_wind_up_when_the_base_cannot_move():
    """A base that never moves: the command stays at the outer loop's feedforward plus the
    inner-loop gain times the max lead, instead of growing with the reference's drift."""
    from wbc.laws.cascade_law import CascadeLaw, CascadeParams

    params = CascadeParams()
    law = CascadeLaw(MODEL, params)
    task = pose_task(MODEL, np.concatenate(([2.0, 0.0, 0.0], HOME[3:])))
    speeds = [np.hypot(*law.step(HOME, task, DT).u[:2]) for _ in range(500)]
    feedforward = speeds[0]
    assert max(speeds) <= feedforward + max(params.k1, params.k2) * params.max_lead + 1e-9
    assert speeds[-1] == pytest.approx(speeds[100], rel=1e-6)


@pytest.mark.parametrize(
    "field, value",
    [
        ("eta", "fast"),
        ("nonholonomic", 1),
        ("obstacle_gain", True),
        ("waist_centring", float("inf")),
    ],
)
def test_gains_of_the_wrong_type_or_not_finite_are_refused(field, value):
    with pytest.raises(ValueError, match=f"LPParams.{field}"):
        LPParams(**{field: value})


def test_the_cascades_point_tracks_the_reference_as_appendix_b_linearises_it():
    """B.2: the point d ahead of the axle moves at the reference point's velocity plus
    diag(k1, k2) times the tracking error, whatever the base's heading."""
    from wbc.laws.cascade_law import CascadeLaw, CascadeParams, offset_point
    from wbc.laws.pinv_law import pinv_velocity

    params = CascadeParams(k1=1.5, k2=3.0)
    task = pose_task(MODEL, np.concatenate(([0.6, 0.3, 0.4], HOME[3:])))
    start = np.concatenate(([0.1, -0.2, 0.7], HOME[3:]))
    d = params.offset

    def point_velocity(q, u):
        phi = q[2]
        return np.array([u[0] - d * np.sin(phi) * u[2], u[1] + d * np.cos(phi) * u[2]])

    def reference_velocity(q, reference):
        error, jacobian = task.error(*MODEL.kinematics(q), q)
        x_dot, y_dot, phi_dot = pinv_velocity(jacobian, error, params.eta)[:3]
        phi = reference[2]
        return np.array([x_dot - d * np.sin(phi) * phi_dot, y_dot + d * np.cos(phi) * phi_dot])

    law = CascadeLaw(MODEL, params)
    first = law.step(start, task, DT).u  # the reference starts on the base: no error
    np.testing.assert_allclose(
        point_velocity(start, first), reference_velocity(start, start), atol=1e-12
    )
    error, jacobian = task.error(*MODEL.kinematics(start), start)
    reference = start[:3] + DT * pinv_velocity(jacobian, error, params.eta)[:3]
    lagging = start.copy()
    lagging[:2] -= [0.01, -0.02]  # the real base has not followed
    u = law.step(lagging, task, DT).u
    target = np.array(offset_point(*reference, d))
    point = np.array(offset_point(*lagging[:3], d))
    expected = reference_velocity(lagging, reference) + np.array([1.5, 3.0]) * (target - point)
    np.testing.assert_allclose(point_velocity(lagging, u), expected, atol=1e-12)
    assert abs(u[0] * np.sin(lagging[2]) - u[1] * np.cos(lagging[2])) < 1e-12  # 5.11


def test_the_error_rate_is_the_difference_over_dt_or_the_commanded_rate():
    """e' = (e - e_last) / dt against the last error of the same task; -eta e at a task's first
    step (no last error); neither input written to."""
    error, last = np.array([0.3, -0.2, 0.0, 1e-3]), np.array([0.1, -0.25, 0.0, 2e-3])
    given = error.copy(), last.copy()
    np.testing.assert_array_equal(error_rate(error, last, 0.6, 0.05), (error - last) / 0.05)
    np.testing.assert_array_equal(error_rate(error, None, 0.6, 0.05), -0.6 * error)
    np.testing.assert_array_equal(error, given[0])
    np.testing.assert_array_equal(last, given[1])
