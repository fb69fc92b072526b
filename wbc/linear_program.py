"""The linear program of eq. 5.29, stacked from a task and constraint rows, solved by HiGHS.

Columns g = [u_P, u_N, y] (each >= 0, u = u_P - u_N); HiGHS takes row bounds directly, so the
slack columns z_A, z_B, z_C of the canonical form 5.29 stay implicit. With task Jacobian
J (m x n), error e and tie-break weight w:

    min   1'(2y - (J u + eta e)) + w 1'(u_P + u_N)   (= ||J u + eta e||_1 + w ||u||_1, 5.4-5.5)
    s.t.  1'u_P + 1'u_N <= limit            for every OneNormBound
          J u_P - J u_N - y <= -eta e
          lower <= A u_P - A u_N <= upper   for every LinearRows
          column bounds on u_P, u_N         from every VelocityBounds

The tie-break weight w >= 0 is not in the dissertation: 5.29 (w = 0) has a whole face of
optimal u whenever the task can be met exactly, and the simplex returns any vertex of it,
often one with a joint at its velocity bound. A small w picks, among the best residuals, a
vertex of least ||u||_1; it stays a vertex, so the solution stays parsimonious (5.30).

One HiGHS model lives across steps. While the shape of the problem holds, each step changes
costs and bounds in place, replaces the rows that hold J and A, and restores the last optimal
basis, so the dual simplex starts from the previous vertex (usually 0 to 8 iterations).
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


class _Layout:
    """Index arrays and buffers for one shape of the problem, built once per shape."""

    def __init__(self, m: int, n: int, linear_rows: int, norm_rows: int) -> None:
        self.m, self.n, self.norm_rows = m, n, norm_rows
        self.columns = 2 * n + m
        self.varying_rows = m + linear_rows
        self.column_index = np.arange(self.columns, dtype=np.int32)
        self.norm_index = np.arange(norm_rows, dtype=np.int32)
        self.norm_lower = np.full(norm_rows, -INF)
        self.varying_index = np.arange(norm_rows, norm_rows + self.varying_rows, dtype=np.int32)
        # Rows [J -J -I] then [A -A 0], dense: every entry passed, zeros included.
        self.matrix = np.zeros((self.varying_rows, self.columns))
        self.matrix[np.arange(m), 2 * n + np.arange(m)] = -1.0
        self.starts = np.arange(0, self.varying_rows * self.columns, self.columns, dtype=np.int32)
        self.indices = np.tile(self.column_index, self.varying_rows)
        self.row_lower = np.full(self.varying_rows, -INF)
        self.row_upper = np.zeros(self.varying_rows)
        self.cost = np.full(self.columns, 2.0)
        self.col_lower = np.zeros(self.columns)
        self.col_upper = np.full(self.columns, INF)


class WarmStartedLP:
    """One HiGHS model solved once per control step, warm-started from the last basis."""

    def __init__(self) -> None:
        self._highs = highspy.Highs()
        self._layout: _Layout | None = None
        self._basis: object | None = None

    def reset(self) -> None:
        """Forget the previous basis: the next solve starts cold."""
        self._basis = None

    def solve(
        self, jacobian: Array, rhs: Array, rows: list[Rows], velocity_cost: float = 0.0
    ) -> LPSolution:
        """Solve 5.29 for task rows ``J u - y <= rhs`` (rhs = -eta e) and the constraint rows.

        ``velocity_cost`` w adds w ||u||_1 to the objective (0 gives 5.29 exactly).
        """
        m, n = jacobian.shape
        linear: list[LinearRows] = []
        norms: list[OneNormBound] = []
        bounds: list[VelocityBounds] = []
        for rows_ in rows:
            if isinstance(rows_, LinearRows):
                linear.append(rows_)
            elif isinstance(rows_, OneNormBound):
                norms.append(rows_)
            else:
                bounds.append(rows_)
        layout = self._layout_for(m, n, sum(r.matrix.shape[0] for r in linear), len(norms))

        if not bounds:
            bounds.append(VelocityBounds("free", np.full(n, -INF), np.full(n, INF)))
        u_lower, u_upper = bounds[0].lower, bounds[0].upper
        if len(bounds) > 1:
            u_lower, u_upper = u_lower.copy(), u_upper.copy()
            for bound in bounds[1:]:
                np.maximum(u_lower, bound.lower, out=u_lower)
                np.minimum(u_upper, bound.upper, out=u_upper)
            if np.any(u_lower > u_upper):
                return LPSolution(np.zeros(n), "infeasible", None, ())
        # u_P in [max(lower, 0), max(upper, 0)], u_N in [max(-upper, 0), max(-lower, 0)].
        np.maximum(u_lower, 0.0, out=layout.col_lower[:n])
        np.maximum(u_upper, 0.0, out=layout.col_upper[:n])
        np.maximum(-u_upper, 0.0, out=layout.col_lower[n : 2 * n])
        np.maximum(-u_lower, 0.0, out=layout.col_upper[n : 2 * n])
        column_sums = jacobian.sum(axis=0)
        np.subtract(velocity_cost, column_sums, out=layout.cost[:n])
        np.add(velocity_cost, column_sums, out=layout.cost[n : 2 * n])

        matrix = layout.matrix
        matrix[:m, :n] = jacobian
        np.negative(jacobian, out=matrix[:m, n : 2 * n])
        layout.row_upper[:m] = rhs
        row = m
        for rows_ in linear:
            count = rows_.matrix.shape[0]
            matrix[row : row + count, :n] = rows_.matrix
            np.negative(rows_.matrix, out=matrix[row : row + count, n : 2 * n])
            layout.row_lower[row : row + count] = rows_.lower
            layout.row_upper[row : row + count] = rows_.upper
            row += count
        limits = np.array([bound.limit for bound in norms])
        status = self._run(layout, limits)
        if status != "optimal":
            return LPSolution(np.zeros(n), status, None, ())
        values = np.asarray(self._highs.getSolution().col_value)
        u = values[:n] - values[n : 2 * n]
        objective = float(layout.cost @ values + rhs.sum())
        active = _active(u, float(values[: 2 * n].sum()), linear, norms, bounds)
        return LPSolution(u, status, objective, active)

    def _layout_for(self, m: int, n: int, linear_rows: int, norm_rows: int) -> _Layout:
        layout = self._layout
        if layout is None or (layout.m, layout.n, layout.varying_rows - layout.m,
                              layout.norm_rows) != (m, n, linear_rows, norm_rows):  # fmt: skip
            layout = _Layout(m, n, linear_rows, norm_rows)
            self._build(layout)
        return layout

    def _build(self, layout: _Layout) -> None:
        """A new model: the columns, the constant one-norm rows, empty varying rows."""
        highs = self._highs
        highs.clearModel()
        highs.setOptionValue("output_flag", False)
        highs.setOptionValue("solver", "simplex")
        highs.setOptionValue("presolve", "off")
        highs.setOptionValue("primal_feasibility_tolerance", 1e-10)
        empty_int, empty = np.zeros(0, dtype=np.int32), np.zeros(0)
        highs.addCols(layout.columns, layout.cost, layout.col_lower, layout.col_upper, 0,
                      empty_int, empty_int, empty)  # fmt: skip
        width = 2 * layout.n
        count = layout.norm_rows
        if count:
            highs.addRows(count, np.full(count, -INF), np.zeros(count), count * width,
                          np.arange(0, count * width, width, dtype=np.int32),
                          np.tile(np.arange(width, dtype=np.int32), count),
                          np.ones(count * width))  # fmt: skip
        highs.addRows(layout.varying_rows, layout.row_lower, layout.row_upper, 0,
                      np.zeros(layout.varying_rows, dtype=np.int32), empty_int, empty)  # fmt: skip
        self._layout = layout
        self._basis = None

    def _run(self, layout: _Layout, limits: Array) -> str:
        highs = self._highs
        highs.changeColsCost(layout.columns, layout.column_index, layout.cost)
        highs.changeColsBounds(layout.columns, layout.column_index, layout.col_lower,
                               layout.col_upper)  # fmt: skip
        if layout.norm_rows:
            highs.changeRowsBounds(layout.norm_rows, layout.norm_index, layout.norm_lower,
                                   limits)  # fmt: skip
        highs.deleteRows(layout.varying_rows, layout.varying_index)
        highs.addRows(layout.varying_rows, layout.row_lower, layout.row_upper, layout.matrix.size,
                      layout.starts, layout.indices, layout.matrix.ravel())  # fmt: skip
        if self._basis is not None:
            highs.setBasis(self._basis)
        highs.run()
        model_status = highs.getModelStatus()
        if model_status != highspy.HighsModelStatus.kOptimal:
            self._basis = None
            return highs.modelStatusToString(model_status).lower()
        self._basis = highs.getBasis()
        return "optimal"


def _active(
    u: Array,
    split_sum: float,
    linear: list[LinearRows],
    norms: list[OneNormBound],
    bounds: list[VelocityBounds],
) -> tuple[str, ...]:
    """Names of the constraints that hold with equality at the solution.

    Engaged equality rows are active; a one-norm bound when 1'(u_P + u_N) reaches it; a
    velocity bound entry (named ``name[i]``) when u_i sits on a finite, non-degenerate bound.
    """
    active = [rows.name for rows in linear if rows.engaged]
    active += [bound.name for bound in norms if split_sum >= bound.limit - ACTIVE_TOLERANCE]
    for bound in bounds:
        at_bound = (u - bound.lower <= ACTIVE_TOLERANCE) | (bound.upper - u <= ACTIVE_TOLERANCE)
        at_bound &= np.isfinite(bound.upper) & (bound.upper - bound.lower > ACTIVE_TOLERANCE)
        if at_bound.any():
            active += [f"{bound.name}[{i}]" for i in np.flatnonzero(at_bound)]
    return tuple(active)
