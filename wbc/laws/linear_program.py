"""The linear program of eq. 5.29, stacked from cost terms and constraint rows, solved by HiGHS.

Columns g = [u_P, u_N, y] (each >= 0, u = u_P - u_N); HiGHS takes row bounds directly, so the
slack columns z_A, z_B, z_C of the canonical form 5.29 stay implicit. For residual costs
w_b ||A_b u + b_b||_1 (the task is the first, A = J, b = eta e, w = 1) and velocity costs
sum_i c_i |u_i|:

    min   sum_b w_b 1'(2 y_b - (A_b u + b_b)) + c'(u_P + u_N)
    s.t.  A_b u_P - A_b u_N - y_b <= -b_b       for every residual cost (y_b >= max(r_b, 0))
          lower <= u_P - u_N <= upper           the velocity bounds, one row per entry (5.15)
          1'u_P + 1'u_N <= limit                for every OneNormBound (5.10)
          lower <= A u_P - A u_N <= upper       for every LinearRows (5.12, 5.28)

At the optimum 2 y_b - r_b = |r_b|, so the objective is sum_b w_b ||r_b||_1 + c'|u|: with one
residual cost (the task) and c = 0 it is 5.29 exactly. A velocity cost may weigh the two
directions of an entry differently (c_P on u_P, c_N on u_N): still linear, still a vertex.

Every column has the bounds [0, inf), as in 5.29, and the velocity limits are rows on
u_P - u_N as in 5.29's W_l. A nonbasic column is then 0, so every nonzero entry of u comes from
a basic column: at most as many as there are active rows (5.30). Written as column bounds
instead (u_P <= max(upper, 0), u_N <= max(-lower, 0)), a column nonbasic at its upper bound is
nonzero too, and with c = 0 the simplex may return both halves of one u_i positive.

The velocity cost c is not in the dissertation: 5.29 has a whole face of optimal u whenever
the task can be met exactly, and the simplex returns any vertex of it, often one with a joint
at its speed bound. A small c picks, among the best residuals, a vertex of least ||u||_1; it
stays a vertex, so the solution stays parsimonious.

One HiGHS model lives across steps. While the shape of the problem holds, each step changes
costs and row bounds in place, replaces the rows that hold A_b and A, and restores the last
optimal basis, so the dual simplex starts from the previous vertex (usually 0 to 8 iterations).
"""

from __future__ import annotations

import operator
from collections.abc import Callable, Sequence
from typing import NamedTuple

import highspy
import numpy as np

from wbc.laws.active_set import BoundEntries, active
from wbc.laws.basis_reuse import KeptBasis, lapack
from wbc.laws.constraints.base import LinearRows, OneNormBound, Rows, VelocityBounds
from wbc.laws.kept import KEPT
from wbc.laws.lp_layout import INF, Layout, picker
from wbc.laws.objectives.base import Cost, ResidualCost, VelocityCost

Array = np.ndarray
SOLVER_OPTIONS = {
    "output_flag": False,
    "solver": "simplex",
    "presolve": "off",
    "primal_feasibility_tolerance": 1e-10,
    "threads": 1,
}
"""Dual simplex on the model as given. ``threads`` 1: with the default 0, every run() reads the
CPU count and topology from sysfs (seen with strace); the LP step measured 308 us median with
the default and 208 us with threads 1, the two laws stepping in turn on one trajectory of a
loaded 2-core machine."""


class LPSolution(NamedTuple):
    """What one solve gives: u (zeros unless optimal), the status, the objective and the names
    of the active constraints (a named tuple: built at every step in a fraction of the time of
    a frozen dataclass)."""

    u: Array
    status: str
    objective: float | None
    active: tuple[str, ...]
    magnitudes: list[float]
    """|u_i| as Python floats, read for the active set and u's nonzero counts."""


class WarmStartedLP:
    """One HiGHS model solved once per control step, warm-started from the last basis.

    Before calling HiGHS, a step tests whether the last optimal basis is still optimal for
    its data (wbc.laws.basis_reuse); when it is, the vertex comes from that basis directly.
    """

    def __init__(self) -> None:
        self._highs = highspy.Highs()
        lapack()  # SciPy's LAPACK loaded with the LP, not in its first step
        for option, value in SOLVER_OPTIONS.items():
            self._highs.setOptionValue(option, value)
        self._layout: Layout | None = None
        self._basis: KeptBasis | None = None
        self._costs: list[VelocityCost] = []
        self._cost_key: tuple[int, ...] = ()
        self._cost_sums: tuple[Array, Array] = (np.zeros(0), np.zeros(0))
        self._kinds = _Kinds(())
        self._entries: dict[tuple[str, int], BoundEntries] = {}
        """The entries of each velocity bound seen, by its name and size (``active``)."""

    def reset(self) -> None:
        """Forget the previous basis: the next solve starts cold."""
        self._basis = None

    def solve(self, costs: list[Cost], rows: list[Rows]) -> LPSolution:
        """Minimise the sum of ``costs`` over u subject to ``rows`` (5.29)."""
        items = (*costs, *rows)
        kinds = self._kinds
        if tuple(map(type, items)) != kinds.types:
            kinds = self._kinds = _Kinds(tuple(map(type, items)))
        residuals, linear = kinds.residual(items), kinds.linear(items)
        bounds, norms = kinds.bounds(items), kinds.norms(items)
        matrices = list(map(_MATRIX, kinds.matrices(items)))
        n = matrices[0].shape[1]
        layout = self._layout
        if layout is None or layout.kinds is not kinds or layout.counts != (n, *map(len, matrices)):
            layout = self._layout_for(matrices, len(residuals), len(norms))
        u_lower, u_upper = layout.u_lower, layout.u_upper
        # Each bound's entries as Python floats, for the test below and the active set.
        if len(bounds) == 1:
            (bound,) = bounds
            lows, highs = bound.lower.tolist(), bound.upper.tolist()
            entries = self._entries.get((bound.name, n)) or self._entries_of(
                bound.name, lows, highs
            )
            limits = [(entries, lows, highs)]
            u_lower[...], u_upper[...] = bound.lower, bound.upper
            infeasible = not bound.ordered and any(map(operator.gt, lows, highs))
        else:
            limits = []
            for bound in bounds:
                lows, highs = bound.lower.tolist(), bound.upper.tolist()
                limits.append((self._entries_of(bound.name, lows, highs), lows, highs))
            u_lower.fill(-INF)
            u_upper.fill(INF)
            for bound in bounds:
                np.maximum(u_lower, bound.lower, out=u_lower)
                np.minimum(u_upper, bound.upper, out=u_upper)
            infeasible = bool(np.count_nonzero(u_lower > u_upper))
        if infeasible:
            return _failed(n, "infeasible")
        for row, bound in enumerate(norms, n):
            layout.upper[row] = bound.limit

        # The varying rows: [A_b -A_b -I_b] of every residual cost, then [A -A 0] of the rows.
        layout.fill(matrices, map(_OFFSET, residuals))
        if len(layout.filled) == 1:
            only, kept = linear[layout.filled[0]], layout.linear_sources
            if only.lower is not kept[0] or id(only.lower) not in KEPT:
                layout.linear_lower[...] = kept[0] = only.lower
            if only.upper is not kept[1] or id(only.upper) not in KEPT:
                layout.linear_upper[...] = kept[1] = only.upper
        elif layout.filled:
            np.concatenate([linear[i].lower for i in layout.filled], out=layout.linear_lower)
            np.concatenate([linear[i].upper for i in layout.filled], out=layout.linear_upper)
        weights = list(map(_WEIGHT, residuals))
        if weights != layout.weights:
            layout.weigh(weights)
        # c_P and c_N, the velocity costs of each entry's two directions (``_optimum``).
        velocity = kinds.velocity(items)
        if (n, *map(id, velocity)) != self._cost_key:
            self._sum_velocity_costs(velocity, n)
        status, u = self._optimum(layout)
        if u is None:
            return _failed(n, status)
        # The vertex's cost less the constant -sum_b w_b 1'b_b (the residual rows' upper bounds
        # hold -b): plus sum_b w_b 1'(-b_b), the same IEEE sum. ndarray.dot: the same BLAS sums
        # as @, in about half the time for vectors this short.
        residual_upper = layout.residual_upper
        objective = float(layout.cost.dot(layout.values) + layout.row_weight.dot(residual_upper))
        values = u.tolist()
        magnitudes = list(map(abs, values))
        named = active(u, values, magnitudes, linear, norms, limits)
        # The named tuple built by tuple.__new__: the same value, without its __new__'s frame.
        return tuple.__new__(LPSolution, (u, status, objective, named, magnitudes))

    def _entries_of(self, name: str, lows: list[float], highs: list[float]) -> BoundEntries:
        """The entries of the velocity bound ``name`` whose entries are ``lows`` and ``highs``,
        made and split at its first step of their size."""
        n = len(lows)
        entries = self._entries.get((name, n))
        if entries is None:
            entries = self._entries[name, n] = BoundEntries(name, n)
            entries.split(lows, highs)
        return entries

    def _sum_velocity_costs(self, costs: Sequence[VelocityCost], n: int) -> None:
        """c_P and c_N, the sums of the velocity costs' weights (``_cost_sums``), kept while the
        terms return the same costs (the same objects, held here so that no other takes their
        ids; a step compares ``_cost_key``) for u of n."""
        self._costs, self._cost_key = costs, (n, *map(id, costs))
        self._cost_sums = (
            sum((cost.weights for cost in costs), np.zeros(n)),
            sum((cost.negative_weights for cost in costs), np.zeros(n)),
        )

    def _layout_for(self, matrices: list[Array], residual_count: int, norm_rows: int) -> Layout:
        """The layout of this step's shape: the last one while the shape holds."""
        key = (tuple(map(_SHAPE, matrices)), residual_count, norm_rows)
        if self._layout is None or self._layout.key != key:
            self._build(Layout(*key))
        assert self._layout is not None
        self._layout.kinds = self._kinds
        return self._layout

    def _build(self, layout: Layout) -> None:
        """A new model: the columns, the fixed velocity and one-norm rows, empty varying rows."""
        highs = self._highs
        highs.clearModel()
        empty_int, empty = np.zeros(0, dtype=np.int32), np.zeros(0)
        highs.addCols(
            layout.columns,
            layout.cost,
            layout.col_lower,
            layout.col_upper,
            0,
            empty_int,
            empty_int,
            empty,
        )
        static = layout.matrix[: layout.static_rows]
        starts = np.arange(0, static.size, layout.columns, dtype=np.int32)
        indices = np.tile(layout.column_index, layout.static_rows)
        highs.addRows(
            layout.static_rows,
            layout.lower[: layout.static_rows],
            layout.upper[: layout.static_rows],
            static.size,
            starts,
            indices,
            static.ravel(),
        )
        highs.addRows(
            layout.varying_rows,
            layout.lower[layout.static_rows :],
            layout.upper[layout.static_rows :],
            0,
            np.zeros(layout.varying_rows, dtype=np.int32),
            empty_int,
            empty,
        )
        self._layout = layout
        self._basis = None

    def _optimum(self, layout: Layout) -> tuple[str, Array | None]:
        """The LP solved from this step's data (``layout``'s buffers, the velocity costs' sums),
        and u = u_P - u_N at its optimal vertex (None where HiGHS finds no optimum), with the
        status.

        The costs of u_P are c_P - sum_b w_b 1'A_b, of u_N c_N + sum_b w_b 1'A_b (rows weighted
        by w), c_P and c_N the velocity costs of each entry's two directions (y_b's 2 w_b are
        set with the weights, ``Layout.weigh``). The vertex comes from the kept basis if it is
        still optimal, else from HiGHS.
        """
        positive, negative = self._cost_sums
        column_sums = layout.row_weight.dot(layout.residual_stack)
        np.subtract(positive, column_sums, layout.cost_positive)
        np.add(negative, column_sums, layout.cost_negative)
        status, values = "optimal", None
        if self._basis is not None:
            values = self._basis.solution(
                layout.matrix, layout.lower, layout.upper, layout.cost, layout.values
            )
        if values is None:
            status, values = self._run(layout)
            if values is None:
                return status, None
        # With no cost on u_P + u_N (c = 0) a vertex may hold both halves of one u_i positive,
        # the one-norm row tight only through that waste (its dual 0). One degenerate pivot away
        # lies the same u with the halves split canonically (each less their minimum); their
        # difference is u_P - u_N bit for bit (IEEE rounding is symmetric, x - x is +0).
        return status, layout.values_plus - layout.values_minus

    def _run(self, layout: Layout) -> tuple[str, Array | None]:
        """Every call into HiGHS of one step: update the model, restore the basis, solve.

        Returns the status and, when optimal, the column values.
        """
        highs = self._highs
        static = layout.static_rows
        highs.changeColsCost(layout.columns, layout.column_index, layout.cost)
        highs.changeRowsBounds(
            static, layout.static_index, layout.lower[:static], layout.upper[:static]
        )
        highs.deleteRows(layout.varying_rows, layout.varying_index)
        highs.addRows(
            layout.varying_rows,
            layout.lower[static:],
            layout.upper[static:],
            layout.varying.size,
            layout.starts,
            layout.indices,
            layout.varying.ravel(),
        )
        if self._basis is not None:
            highs.setBasis(self._basis.highs_basis)
        highs.run()
        model_status = highs.getModelStatus()
        if model_status != highspy.HighsModelStatus.kOptimal:
            self._basis = None
            return highs.modelStatusToString(model_status).lower(), None
        self._basis = KeptBasis(highs.getBasis())
        layout.values[...] = highs.getSolution().col_value
        return "optimal", layout.values


_MATRIX, _OFFSET, _WEIGHT, _SHAPE = map(
    operator.attrgetter, ("matrix", "offset", "weight", "shape")
)
KINDS = (VelocityCost, ResidualCost, LinearRows, VelocityBounds, OneNormBound)
"""What ``WarmStartedLP.solve`` takes, by group (``_Kinds``)."""


class _Kinds:
    """Where each kind of cost or rows sits among one step's items, found once for a sequence
    of types: a step whose terms return the kinds of the last picks them by place.

    One picker per group: the velocity costs, residual costs, linear rows, velocity bounds and
    one-norm bounds, and ``matrices``, the residual costs then the linear rows (those with a
    matrix).
    """

    def __init__(self, types: tuple[type, ...]) -> None:
        self.types = types
        places: list[list[int]] = [[] for _ in KINDS]
        for place, kind in enumerate(types):
            group = next((i for i, base in enumerate(KINDS) if issubclass(kind, base)), None)
            if group is None:
                raise TypeError(f"not a cost or rows of the LP: {kind.__name__}")
            places[group].append(place)
        self.velocity, self.residual, self.linear, self.bounds, self.norms = map(_picker, places)
        self.matrices = _picker(places[1] + places[2])


def _picker(places: list[int]) -> Callable[[tuple], tuple]:
    """The items of a tuple at ``places``: one slice where they follow each other (a group of
    one, most often: no Python call at a step), else ``picker``'s."""
    if places and places == list(range(places[0], places[-1] + 1)):
        return operator.itemgetter(slice(places[0], places[-1] + 1))
    return picker(places)


def _failed(n: int, status: str) -> LPSolution:
    return LPSolution(np.zeros(n), status, None, (), [0.0] * n)
