"""What the LP minimises, on random states: among the velocities with the same task velocity
J u, the LP's u has the least (weighted) 1-norm inside the LP's own constraints (an independent
LP, scipy's, solves that; the pseudoinverse's least 2-norm: test_pinv_law.py)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from scipy.optimize import linprog

from tests.wbc.laws.drawn_states import MODEL, states, unit
from wbc.geometry.scenarios import DT
from wbc.laws.constraints.base import LinearRows, OneNormBound, VelocityBounds
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.step_context import StepContext
from wbc.task import PoseTask

TIE_BREAK_ONLY = LPParams(waist_hold=0.0, base_target=0.0, obstacle_mode="off")


def least_weighted_norm(
    law: LPLaw, q: np.ndarray, task: PoseTask, weights: np.ndarray, u_star: np.ndarray
) -> float:
    """min sum_i w_i |u_i| over u with J u = J u*, inside the law's rows (5.12, 5.15, 5.10)."""
    pose, jacobian = MODEL.kinematics(q)
    error, task_jacobian = task.error(pose, jacobian, q)
    context = StepContext(MODEL, q, error, -law.params.eta * error, task.goal_position[:2])
    n = MODEL.dof
    lower, upper = np.full(n, -np.inf), np.full(n, np.inf)
    equalities, bounds_rows = [task_jacobian], [task_jacobian @ u_star]
    norm_limit = np.inf
    for constraint in law.constraints or ():
        rows = constraint.rows(context)
        if isinstance(rows, OneNormBound):
            norm_limit = min(norm_limit, rows.limit)
        elif isinstance(rows, VelocityBounds):
            lower, upper = np.maximum(lower, rows.lower), np.minimum(upper, rows.upper)
        else:
            assert isinstance(rows, LinearRows) and np.array_equal(rows.lower, rows.upper)
            equalities.append(rows.matrix)
            bounds_rows.append(rows.upper)
    # Variables [u_P, u_N] >= 0, u = u_P - u_N.
    a_eq = np.hstack((np.vstack(equalities), -np.vstack(equalities)))
    b_eq = np.concatenate(bounds_rows)
    speed = np.hstack((np.eye(n), -np.eye(n)))
    a_ub = np.vstack((speed, -speed, np.ones((1, 2 * n))))
    b_ub = np.concatenate((upper, -lower, [norm_limit]))
    finite = np.isfinite(b_ub)
    result = linprog(
        np.concatenate((weights, weights)),
        A_ub=a_ub[finite],
        b_ub=b_ub[finite],
        A_eq=a_eq,
        b_eq=b_eq,
        bounds=(0, None),
        method="highs",
    )
    assert result.status == 0, result.message
    return float(result.fun)


@settings(max_examples=40, deadline=None)
@given(unit, unit)
def test_the_lp_takes_the_least_1_norm_for_its_task_velocity_inside_its_constraints(a, b):
    q, task = states(a, b)
    for params in (TIE_BREAK_ONLY, LPParams(base_target=0.0, obstacle_mode="off")):
        law = LPLaw(MODEL, params)
        out = law.step(q, task, DT)
        assert out.ok
        weights = np.full(MODEL.dof, params.velocity_cost)
        weights[3] += params.waist_hold
        least = least_weighted_norm(law, q, task, weights, out.u)
        assert weights @ np.abs(out.u) <= least + 1e-8
