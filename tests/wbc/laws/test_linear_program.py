"""The LP of eq. 5.29 (wbc/laws/linear_program.py) on small hand-made problems, against SciPy."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from wbc.laws.constraints.base import LinearRows, OneNormBound, Rows, VelocityBounds
from wbc.laws.linear_program import LPSolution, WarmStartedLP
from wbc.laws.objectives.base import ResidualCost, VelocityCost

EQUALITY_TOL = 1e-9
OBJECTIVE_TOL = 1e-8


def solve(
    lp: WarmStartedLP,
    jacobian: np.ndarray,
    rhs: np.ndarray,
    rows: list[Rows],
    velocity_cost: float = 0.0,
) -> LPSolution:
    """min ||J u - rhs||_1 + w ||u||_1 under the rows (rhs = -eta e, as the task gives it)."""
    costs = [
        ResidualCost("task", jacobian, -rhs),
        VelocityCost("velocity", np.full(jacobian.shape[1], velocity_cost)),
    ]
    return lp.solve(costs, rows)


def reference_objective(
    jacobian: np.ndarray, rhs: np.ndarray, rows: list[Rows], velocity_cost: float = 0.0
) -> float:
    """min ||J u - rhs||_1 + w ||u||_1 under the rows, by SciPy on variables [u, t, s].

    |J u - rhs| <= t and |u| <= s, so the optimum is sum(t) + w sum(s).
    """
    m, n = jacobian.shape
    eye_n, zeros_mn, zeros_nm = np.eye(n), np.zeros((m, n)), np.zeros((n, m))
    a_ub = [
        np.hstack((jacobian, -np.eye(m), zeros_mn)),
        np.hstack((-jacobian, -np.eye(m), zeros_mn)),
        np.hstack((eye_n, zeros_nm, -eye_n)),
        np.hstack((-eye_n, zeros_nm, -eye_n)),
    ]
    b_ub = [rhs, -rhs, np.zeros(n), np.zeros(n)]
    a_eq, b_eq = [], []
    lower, upper = np.full(n, -np.inf), np.full(n, np.inf)
    for row in rows:
        if isinstance(row, VelocityBounds):
            lower, upper = np.maximum(lower, row.lower), np.minimum(upper, row.upper)
        elif isinstance(row, OneNormBound):
            a_ub.append(np.concatenate((np.zeros(n + m), np.ones(n)))[None, :])
            b_ub.append([row.limit])
        else:
            padded = np.hstack((row.matrix, np.zeros((row.matrix.shape[0], m + n))))
            equal = row.lower == row.upper
            a_eq.append(padded[equal])
            b_eq.append(row.lower[equal])
            finite_upper = ~equal & np.isfinite(row.upper)
            finite_lower = ~equal & np.isfinite(row.lower)
            a_ub += [padded[finite_upper], -padded[finite_lower]]
            b_ub += [row.upper[finite_upper], -row.lower[finite_lower]]
    cost = np.concatenate((np.zeros(n), np.ones(m), np.full(n, velocity_cost)))
    bounds = list(zip(lower, upper, strict=True)) + [(0, None)] * (m + n)
    result = linprog(
        cost,
        A_ub=np.vstack(a_ub),
        b_ub=np.concatenate(b_ub),
        A_eq=np.vstack(a_eq) if a_eq else None,
        b_eq=np.concatenate(b_eq) if b_eq else None,
        bounds=bounds,
        method="highs",
    )
    assert result.status == 0, result.message
    return float(result.fun)


def random_problem(seed: int) -> tuple[np.ndarray, np.ndarray, list[Rows]]:
    """A task of m rows on n joints with a velocity box, one equality row and a 1-norm bound."""
    rng = np.random.default_rng(seed)
    m, n = int(rng.integers(2, 7)), int(rng.integers(3, 9))
    jacobian = rng.normal(size=(m, n))
    rhs = -0.6 * rng.normal(size=m)  # rhs = -eta e
    speed = rng.uniform(0.2, 1.5, n)
    equality = rng.normal(size=(1, n))
    rows: list[Rows] = [
        VelocityBounds("speed", -speed, speed),
        LinearRows("equality", equality, np.zeros(1), np.zeros(1)),
        OneNormBound("norm", float(rng.uniform(0.1, 3.0))),
    ]
    return jacobian, rhs, rows


def residual_norm(jacobian: np.ndarray, rhs: np.ndarray, u: np.ndarray) -> float:
    return float(np.abs(jacobian @ u - rhs).sum())


def assert_feasible(u: np.ndarray, rows: list[Rows]) -> None:
    for row in rows:
        if isinstance(row, VelocityBounds):
            assert np.all(u >= row.lower - EQUALITY_TOL) and np.all(u <= row.upper + EQUALITY_TOL)
        elif isinstance(row, OneNormBound):
            assert np.abs(u).sum() <= row.limit + EQUALITY_TOL
        else:
            value = row.matrix @ u
            assert np.all(value >= row.lower - EQUALITY_TOL)
            assert np.all(value <= row.upper + EQUALITY_TOL)


# --- Optimality -------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(20))
def test_minimises_the_one_norm_of_the_task_residual(seed: int) -> None:
    jacobian, rhs, rows = random_problem(seed)
    solution = solve(WarmStartedLP(), jacobian, rhs, rows)
    assert solution.status == "optimal"
    assert_feasible(solution.u, rows)
    expected = reference_objective(jacobian, rhs, rows)
    assert solution.objective == pytest.approx(expected, abs=OBJECTIVE_TOL)
    assert residual_norm(jacobian, rhs, solution.u) == pytest.approx(expected, abs=OBJECTIVE_TOL)


@pytest.mark.parametrize("seed", range(10))
def test_velocity_cost_adds_the_weighted_one_norm_of_u(seed: int) -> None:
    jacobian, rhs, rows = random_problem(seed)
    weight = 0.05
    solution = solve(WarmStartedLP(), jacobian, rhs, rows, velocity_cost=weight)
    assert solution.status == "optimal"
    expected = reference_objective(jacobian, rhs, rows, weight)
    achieved = residual_norm(jacobian, rhs, solution.u) + weight * np.abs(solution.u).sum()
    assert solution.objective == pytest.approx(expected, abs=OBJECTIVE_TOL)
    assert achieved == pytest.approx(expected, abs=OBJECTIVE_TOL)


def test_exactly_solvable_task_is_solved_exactly() -> None:
    """With J invertible and no active constraint, u = J^-1 rhs and the objective is 0."""
    jacobian = np.array([[2.0, 1.0], [0.0, 1.0]])
    rhs = np.array([0.3, -0.1])
    solution = solve(WarmStartedLP(), jacobian, rhs, [])
    assert solution.status == "optimal"
    np.testing.assert_allclose(solution.u, np.linalg.solve(jacobian, rhs), atol=1e-12)
    assert solution.objective == pytest.approx(0.0, abs=1e-12)


# --- Constraints ------------------------------------------------------------------------------


def test_velocity_bounds_that_exclude_zero() -> None:
    """Bounds [0.2, 0.5] and [-0.5, -0.2]: with nothing to do, u sits on the bound nearest 0."""
    bounds = VelocityBounds("band", np.array([0.2, -0.5]), np.array([0.5, -0.2]))
    solution = solve(WarmStartedLP(), np.eye(2), np.zeros(2), [bounds])
    assert solution.status == "optimal"
    np.testing.assert_allclose(solution.u, [0.2, -0.2], atol=1e-12)
    assert solution.objective == pytest.approx(0.4)


def test_velocity_bounds_clip_a_far_target() -> None:
    bounds = VelocityBounds("band", np.array([0.2, -0.5]), np.array([0.5, -0.2]))
    solution = solve(WarmStartedLP(), np.eye(2), np.array([3.0, -3.0]), [bounds])
    np.testing.assert_allclose(solution.u, [0.5, -0.5], atol=1e-12)
    assert solution.objective == pytest.approx(5.0)
    target_inside = solve(WarmStartedLP(), np.eye(2), np.array([0.3, -0.4]), [bounds])
    np.testing.assert_allclose(target_inside.u, [0.3, -0.4], atol=1e-12)


@pytest.mark.parametrize(
    ("lower", "upper"),
    [(0.2, 0.5), (-0.5, -0.2), (-0.3, 0.7), (0.0, 0.0), (-np.inf, -0.2), (0.3, np.inf)],
)
def test_velocity_bounds_are_covered_exactly(lower: float, upper: float) -> None:
    """Through the split u = u_P - u_N, u reaches both ends of [lower, upper] and no further."""
    bounds = VelocityBounds("band", np.array([lower]), np.array([upper]))
    for target, end in ((10.0, upper), (-10.0, lower)):
        solution = solve(WarmStartedLP(), np.eye(1), np.array([target]), [bounds])
        assert solution.status == "optimal"
        expected = end if np.isfinite(end) else target
        np.testing.assert_allclose(solution.u, [expected], atol=1e-12)


def test_several_velocity_bounds_intersect() -> None:
    wide = VelocityBounds("wide", np.full(3, -1.0), np.full(3, 1.0))
    narrow = VelocityBounds("narrow", np.array([-0.1, 0.3, -np.inf]), np.array([0.1, 0.6, 0.2]))
    solution = solve(WarmStartedLP(), np.eye(3), np.array([5.0, 5.0, 5.0]), [wide, narrow])
    np.testing.assert_allclose(solution.u, [0.1, 0.6, 0.2], atol=1e-12)


def test_contradictory_velocity_bounds_are_infeasible() -> None:
    """[0.2, 0.5] and [-0.5, -0.2] on the same entry leave no u: the LP must not pretend."""
    positive = VelocityBounds("positive", np.array([0.2]), np.array([0.5]))
    negative = VelocityBounds("negative", np.array([-0.5]), np.array([-0.2]))
    solution = solve(WarmStartedLP(), np.eye(1), np.zeros(1), [positive, negative])
    assert solution.status != "optimal", f"u = {solution.u} violates one of the bounds"
    np.testing.assert_array_equal(solution.u, [0.0])


def test_equality_rows_hold() -> None:
    """The nonholonomic row [sin phi, -cos phi, 0] u = 0 holds while the task pulls off-heading.

    The target (0.5, 0.5) is best met along the heading by u = (0.5, 0.5 tan phi, 0).
    """
    phi = 0.4
    row = LinearRows(
        "nonholonomic", np.array([[np.sin(phi), -np.cos(phi), 0.0]]), np.zeros(1), np.zeros(1)
    )
    speed = VelocityBounds("speed", np.full(3, -1.0), np.full(3, 1.0))
    jacobian = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    solution = solve(WarmStartedLP(), jacobian, np.array([0.5, 0.5]), [row, speed])
    assert solution.status == "optimal"
    assert abs((row.matrix @ solution.u)[0]) <= EQUALITY_TOL
    np.testing.assert_allclose(solution.u, [0.5, 0.5 * np.tan(phi), 0.0], atol=1e-9)
    assert solution.objective == pytest.approx(0.5 - 0.5 * np.tan(phi), abs=OBJECTIVE_TOL)
    assert "nonholonomic" in solution.active


def test_inequality_rows_hold() -> None:
    row = LinearRows("sum", np.array([[1.0, 1.0]]), np.array([-0.3]), np.array([0.3]))
    solution = solve(WarmStartedLP(), np.eye(2), np.array([1.0, 1.0]), [row])
    assert solution.status == "optimal"
    assert (row.matrix @ solution.u)[0] == pytest.approx(0.3, abs=EQUALITY_TOL)
    assert solution.objective == pytest.approx(1.7, abs=OBJECTIVE_TOL)


def test_one_norm_bound_holds_and_is_reported_active() -> None:
    bound = OneNormBound("error_derivative_bound", 0.5)
    solution = solve(WarmStartedLP(), np.eye(3), np.array([1.0, -2.0, 0.5]), [bound])
    assert solution.status == "optimal"
    assert np.abs(solution.u).sum() == pytest.approx(0.5, abs=EQUALITY_TOL)
    assert solution.objective == pytest.approx(3.5 - 0.5, abs=OBJECTIVE_TOL)
    assert "error_derivative_bound" in solution.active


def test_zero_one_norm_bound_stops_every_joint() -> None:
    solution = solve(WarmStartedLP(), np.eye(3), np.ones(3), [OneNormBound("stop", 0.0)])
    assert solution.status == "optimal"
    np.testing.assert_allclose(solution.u, np.zeros(3), atol=1e-12)


# --- Failures and warm starts -----------------------------------------------------------------


def infeasible_rows() -> list[Rows]:
    """u_0 = 1 while |u_0| <= 0.5."""
    return [
        LinearRows("pin", np.array([[1.0, 0.0]]), np.ones(1), np.ones(1)),
        VelocityBounds("speed", np.full(2, -0.5), np.full(2, 0.5)),
    ]


def test_infeasible_problem_returns_zero_without_raising() -> None:
    solution = solve(WarmStartedLP(), np.eye(2), np.array([0.2, 0.2]), infeasible_rows())
    assert solution.status != "optimal"
    np.testing.assert_array_equal(solution.u, np.zeros(2))
    assert solution.objective is None


def test_infeasible_one_norm_bound_returns_zero() -> None:
    rows: list[Rows] = [
        LinearRows("pin", np.array([[1.0, 0.0]]), np.ones(1), np.ones(1)),
        OneNormBound("norm", 0.5),
    ]
    solution = solve(WarmStartedLP(), np.eye(2), np.zeros(2), rows)
    assert solution.status != "optimal"
    np.testing.assert_array_equal(solution.u, np.zeros(2))


def test_a_feasible_problem_after_an_infeasible_one_is_solved() -> None:
    lp = WarmStartedLP()
    jacobian, rhs, rows = random_problem(3)
    cold = solve(WarmStartedLP(), jacobian, rhs, rows)
    assert solve(lp, np.eye(2), np.zeros(2), infeasible_rows()).status != "optimal"
    after = solve(lp, jacobian, rhs, rows)
    assert after.status == "optimal"
    assert after.objective == pytest.approx(cold.objective, abs=OBJECTIVE_TOL)


@pytest.mark.parametrize("seed", range(5))
def test_warm_started_solve_gives_the_same_objective(seed: int) -> None:
    lp = WarmStartedLP()
    jacobian, rhs, rows = random_problem(seed)
    first = solve(lp, jacobian, rhs, rows)
    second = solve(lp, jacobian, rhs, rows)
    assert second.status == first.status == "optimal"
    assert second.objective == pytest.approx(first.objective, abs=OBJECTIVE_TOL)
    assert residual_norm(jacobian, rhs, second.u) == pytest.approx(first.objective, abs=1e-8)


def test_warm_start_across_different_problems_of_one_shape() -> None:
    """A basis kept from one problem must not change the optimum of the next."""
    lp = WarmStartedLP()
    rng = np.random.default_rng(7)
    jacobian, rhs, rows = random_problem(11)
    for _ in range(10):
        step_rhs = rhs + 0.3 * rng.normal(size=rhs.size)
        step_jacobian = jacobian + 0.1 * rng.normal(size=jacobian.shape)
        warm = solve(lp, step_jacobian, step_rhs, rows)
        expected = reference_objective(step_jacobian, step_rhs, rows)
        assert warm.status == "optimal"
        assert warm.objective == pytest.approx(expected, abs=OBJECTIVE_TOL)
        assert_feasible(warm.u, rows)


def test_problems_of_changing_shape_share_one_solver() -> None:
    lp = WarmStartedLP()
    for seed in (1, 2, 1, 4):
        jacobian, rhs, rows = random_problem(seed)
        solution = solve(lp, jacobian, rhs, rows)
        assert solution.u.shape == (jacobian.shape[1],)
        assert solution.objective == pytest.approx(
            reference_objective(jacobian, rhs, rows), abs=OBJECTIVE_TOL
        )


def test_reset_forgets_the_basis_only() -> None:
    lp = WarmStartedLP()
    jacobian, rhs, rows = random_problem(5)
    first = solve(lp, jacobian, rhs, rows)
    lp.reset()
    again = solve(lp, jacobian, rhs, rows)
    assert again.objective == pytest.approx(first.objective, abs=OBJECTIVE_TOL)


def test_rows_of_another_width_than_u_are_refused_naming_it() -> None:
    jacobian, rhs, rows = random_problem(3)
    n = jacobian.shape[1]
    narrow = LinearRows("narrow", np.ones((1, n - 1)), np.zeros(1), np.zeros(1))
    with pytest.raises(ValueError, match=f"needs {n} columns, got one of \\(1, {n - 1}\\)"):
        solve(WarmStartedLP(), jacobian, rhs, [*rows, narrow])
