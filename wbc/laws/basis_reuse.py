"""The simplex optimality test of a kept basis on new data: a solve without calling the solver.

For min c'x subject to lower <= A x <= upper and x >= 0, a basis names m basic variables
among the columns x and the row activities r = A x; every nonbasic column is 0 and every
nonbasic row sits at the bound its status names. With B = [A_J, -I_I] (J the basic columns,
I the basic rows) the basic values solve B z = r_N, the nonbasic row bounds. The basis is
optimal for the new data when
    x_J >= 0 and lower_I <= r_I <= upper_I                     (primal feasible)
    d = c - A'y >= 0 on nonbasic columns, with B'y = [c_J, 0]  (dual feasible)
    y_i >= 0 at a lower row bound, y_i <= 0 at an upper one.
That is the test the dual simplex makes before its first iteration; when it holds, HiGHS would
return this same vertex after 0 iterations.

Between two control steps the optimal basis rarely changes (0 simplex iterations at the median
step of the bench trajectory), and a HiGHS run() costs about 90 us even then (model checks, a
new factorisation, and per-run reads of the CPU topology in sysfs), against about 40 us for
this test in NumPy (the ``vertex`` part of the LP step in `parsimony bench`).

The LU factorisation and its solves are LAPACK's dgetrf and dgetrs as SciPy builds them,
imported when the first LP is made (``lapack``): importing scipy.linalg costs about 0.18 s
of a process's start, which a process with no LP (the QP's controller, the tools that read
the LP's gains) need not pay. NumPy's own solver (numpy.linalg.solve, dgesv) is not used: on
the zoo's closed loops it gave basic values differing in their last bits from SciPy's in 6%
of the bases tested (105 of 1794), so the commands would change.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import highspy
import numpy as np

Array = np.ndarray
PRIMAL_TOLERANCE = 1e-10
DUAL_TOLERANCE = 1e-7
"""HiGHS's primal feasibility tolerance as we set it, and its default dual one."""
PIVOT_TOLERANCE = 1e-9
"""A factor of B with a pivot this small, relative to the largest, is not trusted."""

BASIC = highspy.HighsBasisStatus.kBasic
AT_LOWER = highspy.HighsBasisStatus.kLower
AT_UPPER = highspy.HighsBasisStatus.kUpper


@functools.cache
def lapack() -> tuple[Callable, Callable]:
    """SciPy's dgetrf and dgetrs (LU factorisation, and solves with it), imported once, when
    first asked for (``WarmStartedLP`` asks when it is made, not at its first step)."""
    from scipy.linalg.lapack import dgetrf, dgetrs

    return dgetrf, dgetrs


class KeptBasis:
    """An optimal HiGHS basis, ready to be tested and reused on the next step's data."""

    def __init__(self, highs_basis: highspy.HighsBasis) -> None:
        self.highs_basis = highs_basis
        column_basic = np.array([status == BASIC for status in highs_basis.col_status])
        row_status = list(highs_basis.row_status)
        row_basic = np.array([status == BASIC for status in row_status])
        self.at_lower = np.array([status == AT_LOWER for status in row_status])
        self.at_upper = np.array([status == AT_UPPER for status in row_status])
        self.free = ~(row_basic | self.at_lower | self.at_upper)
        self.basic_columns = np.flatnonzero(column_basic)
        self.nonbasic_columns = ~column_basic
        self.basic_rows = np.flatnonzero(row_basic)
        self.dual_sign = self.at_lower.astype(float) - self.at_upper
        """+1 where a row sits at its lower bound (its dual must be >= 0), -1 at its upper."""
        rows = len(row_status)
        self.valid = len(self.basic_columns) + len(self.basic_rows) == rows
        # B = [A_J, -I_I]: the slack part is fixed by the basis, A_J is filled per test.
        self._matrix = np.zeros((rows, rows))
        slack_columns = len(self.basic_columns) + np.arange(len(self.basic_rows))
        self._matrix[self.basic_rows, slack_columns] = -1.0
        self._basic_cost = np.zeros(rows)

    def solution(
        self, matrix: Array, lower: Array, upper: Array, cost: Array, out: Array
    ) -> Array | None:
        """The column values at this basis, written into ``out``, if it is optimal for the data
        given, else None (``out`` untouched)."""
        if not self.valid:
            return None
        basic, rows = self.basic_columns, self.basic_rows
        getrf, getrs = lapack()
        count = len(basic)
        self._matrix[:, :count] = matrix[:, basic]
        rhs = np.where(self.at_lower, lower, np.where(self.at_upper, upper, 0.0))
        # Each test counts what fails it (np.count_nonzero): any(), all() and min() of a short
        # array cost NumPy 2 several times as much.
        if np.count_nonzero(np.isfinite(rhs)) != rhs.size:
            return None
        factor, pivot_rows, info = getrf(self._matrix)
        if info != 0:
            return None
        pivots = np.abs(factor.diagonal()).tolist()
        if min(pivots) <= PIVOT_TOLERANCE * max(pivots):
            return None
        values = getrs(factor, pivot_rows, rhs)[0]
        basic_values, activities = values[:count], values[count:]
        if (
            np.count_nonzero(basic_values < -PRIMAL_TOLERANCE)
            or np.count_nonzero(activities < lower[rows] - PRIMAL_TOLERANCE)
            or np.count_nonzero(activities > upper[rows] + PRIMAL_TOLERANCE)
        ):
            return None
        self._basic_cost[:count] = cost[basic]
        duals = getrs(factor, pivot_rows, self._basic_cost, trans=1)[0]
        reduced = cost - matrix.T @ duals
        if (
            np.count_nonzero(reduced[self.nonbasic_columns] < -DUAL_TOLERANCE)
            or np.count_nonzero((self.dual_sign * duals < -DUAL_TOLERANCE) & (lower != upper))
            or np.count_nonzero(np.abs(duals[self.free]) > DUAL_TOLERANCE)
        ):
            return None
        out.fill(0.0)
        out[basic] = np.maximum(basic_values, 0.0)
        return out
