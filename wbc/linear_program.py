"""The linear program of eq. 5.29, stacked from a task and constraint rows, solved by HiGHS.

Columns g = [u_P, u_N, y] (each >= 0, u = u_P - u_N); HiGHS takes row bounds directly, so the
slack columns z_A, z_B, z_C of the canonical form 5.29 stay implicit. With task Jacobian
J (m x n) and error e:

    min   1'(2y - (J u + eta e)) + w 1'(u_P + u_N)   (= ||J u + eta e||_1 + w ||u||_1, 5.4-5.5)
    s.t.  J u_P - J u_N - y <= -eta e
          lower <= A u_P - A u_N <= upper   for every LinearRows
          1'u_P + 1'u_N <= limit            for every OneNormBound
          column bounds on u_P, u_N         from every VelocityBounds

The tie-break weight w >= 0 is not in the dissertation: 5.29 (w = 0) has a whole face of
optimal u whenever the task can be met exactly, and the simplex returns any vertex of it,
often one with a joint at its velocity bound. A small w picks, among the best residuals, a
vertex of least ||u||_1; it stays a vertex, so the solution stays parsimonious (5.30).

One HiGHS model lives across steps; each step passes the new arrays and, when the shape is
unchanged, the previous optimal basis, so the dual simplex starts from the last vertex.
"""

from __future__ import annotations

from dataclasses import dataclass

import highspy
import numpy as np

from wbc.constraints.base import LinearRows, OneNormBound, Rows, VelocityBounds

Array = np.ndarray
INF = highspy.kHighsInf
ACTIVE_TOLERANCE = 1e-7


@dataclass(frozen=True)
class LPSolution:
    """What one solve gives: u (zeros unless optimal), the status, objective and active rows."""

    u: Array
    status: str
    objective: float | None
    active: tuple[str, ...]


def split_bounds(lower: Array, upper: Array) -> tuple[Array, Array, Array, Array]:
    """Column bounds of u_P and u_N such that u_P - u_N covers exactly [lower, upper]."""
    return (
        np.maximum(lower, 0.0),
        np.maximum(upper, 0.0),
        np.maximum(-upper, 0.0),
        np.maximum(-lower, 0.0),
    )


class WarmStartedLP:
    """One HiGHS model solved once per control step, warm-started from the last basis."""

    def __init__(self) -> None:
        self._highs = highspy.Highs()
        self._highs.setOptionValue("output_flag", False)
        self._highs.setOptionValue("solver", "simplex")
        self._highs.setOptionValue("presolve", "off")
        self._highs.setOptionValue("primal_feasibility_tolerance", 1e-10)
        self._basis: object | None = None
        self._shape: tuple[int, int] | None = None

    def reset(self) -> None:
        """Forget the previous basis: the next solve starts cold."""
        self._basis = None
        self._shape = None

    def solve(
        self, jacobian: Array, rhs: Array, rows: list[Rows], velocity_cost: float = 0.0
    ) -> LPSolution:
        """Solve 5.29 for task rows ``J u - y <= rhs`` (rhs = -eta e) and the constraint rows.

        ``velocity_cost`` w adds w ||u||_1 to the objective (0 gives 5.29 exactly).
        """
        m, n = jacobian.shape
        linear = [r for r in rows if isinstance(r, LinearRows)]
        norms = [r for r in rows if isinstance(r, OneNormBound)]
        bounds = [r for r in rows if isinstance(r, VelocityBounds)]

        u_lower, u_upper = np.full(n, -INF), np.full(n, INF)
        for bound in bounds:
            u_lower = np.maximum(u_lower, bound.lower)
            u_upper = np.minimum(u_upper, bound.upper)
        u_lower = np.minimum(u_lower, u_upper)
        p_low, p_up, n_low, n_up = split_bounds(u_lower, u_upper)

        a_u = np.vstack([jacobian] + [r.matrix for r in linear])
        num_rows = a_u.shape[0] + len(norms)
        # Dense column-major blocks: [A; 1'] for u_P, [-A; 1'] for u_N, [-I; 0] for y.
        dense = np.zeros((num_rows, 2 * n + m))
        dense[: a_u.shape[0], :n] = a_u
        dense[: a_u.shape[0], n : 2 * n] = -a_u
        dense[a_u.shape[0] :, : 2 * n] = 1.0
        dense[np.arange(m), 2 * n + np.arange(m)] = -1.0
        row_lower = np.concatenate(
            [np.full(m, -INF)] + [r.lower for r in linear] + [np.full(len(norms), -INF)]
        )
        row_upper = np.concatenate([rhs] + [r.upper for r in linear] + [[b.limit for b in norms]])
        column_sums = jacobian.sum(axis=0)
        cost = np.concatenate(
            (velocity_cost - column_sums, velocity_cost + column_sums, np.full(m, 2.0))
        )
        col_lower = np.concatenate((p_low, n_low, np.zeros(m)))
        col_upper = np.concatenate((p_up, n_up, np.full(m, INF)))
        self._pass(dense, cost, float(rhs.sum()), col_lower, col_upper, row_lower, row_upper)

        status = self._run(dense.shape)
        if status != "optimal":
            return LPSolution(np.zeros(n), status, None, ())
        values = np.asarray(self._highs.getSolution().col_value)
        u = values[:n] - values[n : 2 * n]
        objective = float(self._highs.getInfo().objective_function_value)
        return LPSolution(u, status, objective, _active(u, values[: 2 * n], linear, norms, bounds))

    def _pass(self, dense: Array, cost: Array, offset: float, col_lower: Array,
              col_upper: Array, row_lower: Array, row_upper: Array) -> None:
        columns = dense.T
        mask = columns != 0.0
        a_start = np.concatenate(([0], np.cumsum(mask.sum(axis=1)))).astype(np.int32)
        a_index = np.nonzero(mask)[1].astype(np.int32)
        num_rows, num_cols = dense.shape
        self._highs.passModel(
            num_cols, num_rows, int(a_start[-1]), highspy.MatrixFormat.kColwise,
            highspy.ObjSense.kMinimize, offset, cost, col_lower, col_upper,
            row_lower, row_upper, a_start, a_index, columns[mask],
            np.zeros(num_cols, dtype=np.int32),
        )  # fmt: skip

    def _run(self, shape: tuple[int, int]) -> str:
        if self._basis is not None and self._shape == shape:
            self._highs.setBasis(self._basis)
        self._highs.run()
        model_status = self._highs.getModelStatus()
        if model_status != highspy.HighsModelStatus.kOptimal:
            self.reset()
            return self._highs.modelStatusToString(model_status).lower()
        self._basis = self._highs.getBasis()
        self._shape = shape
        return "optimal"


def _active(
    u: Array,
    split: Array,
    linear: list[LinearRows],
    norms: list[OneNormBound],
    bounds: list[VelocityBounds],
) -> tuple[str, ...]:
    """Names of the rows that hold with equality at the solution (engaged equalities included)."""
    active = [r.name for r in linear if r.engaged and _tight(r, u)]
    active += [b.name for b in norms if split.sum() >= b.limit - ACTIVE_TOLERANCE]
    for bound in bounds:
        at = (np.abs(u - bound.lower) <= ACTIVE_TOLERANCE) | (
            np.abs(u - bound.upper) <= ACTIVE_TOLERANCE
        )
        at &= np.isfinite(bound.lower) & (bound.upper - bound.lower > ACTIVE_TOLERANCE)
        active += [f"{bound.name}[{i}]" for i in np.flatnonzero(at)]
    return tuple(active)


def _tight(rows: LinearRows, u: Array) -> bool:
    value = rows.matrix @ u
    return bool(
        np.any(np.abs(value - rows.lower) <= ACTIVE_TOLERANCE)
        or np.any(np.abs(value - rows.upper) <= ACTIVE_TOLERANCE)
    )
