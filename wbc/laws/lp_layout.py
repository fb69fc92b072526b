"""The buffers of the linear program 5.29 for one shape of the problem, built once per shape.

A step of ``wbc.laws.linear_program.WarmStartedLP`` writes its data into views of these buffers
(no array of the program is made at a step), and the kept basis test and HiGHS read them.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Iterable, Sequence

import highspy
import numpy as np

from wbc.laws.kept import KEPT

Array = np.ndarray
INF = highspy.kHighsInf


class Layout:
    """Index arrays and buffers for one shape of the problem.

    Columns g = [u_P, u_N, y]. Rows: the n velocity rows and the one-norm rows first (fixed
    coefficients, bounds change), then the residual rows and the linear rows (replaced every
    step). ``matrix`` holds them all, dense; ``varying`` is a view of its last rows, as passed to
    HiGHS. ``stack`` holds the varying rows' A_b and A contiguous, as a step stacks them, before
    they are copied to ``plus`` and, negated, to ``minus``: NumPy negates and copies between
    contiguous arrays with less of its per-call work than into or from strided views.
    """

    def __init__(
        self, shapes: tuple[tuple[int, int], ...], residual_count: int, norm_rows: int
    ) -> None:
        n = shapes[0][1]
        counts = [rows for rows, _ in shapes]
        for shape in shapes:
            if shape[1] != n:
                raise ValueError(f"every matrix of the LP needs {n} columns, got one of {shape}")
        self.key = (shapes, residual_count, norm_rows)
        """What makes two steps' problems one shape: the shapes of the residual costs' and the
        linear rows' matrices, how many of them are residual costs, and the one-norm rows."""
        self.n, self.norm_rows = n, norm_rows
        self.counts = (n, *counts)
        """n and the rows of each matrix, as a step checks them."""
        self.kinds: object = None
        """The kinds of costs and rows (``linear_program``) this layout was last taken for."""
        residual_rows = counts[:residual_count]
        linear_rows = sum(counts[residual_count:])
        residual_total = self.residual_rows = sum(residual_rows)
        self.columns = 2 * n + residual_total
        static = self.static_rows = n + norm_rows
        self.varying_rows = residual_total + linear_rows
        rows = self.static_rows + self.varying_rows
        self.column_index = np.arange(self.columns, dtype=np.int32)
        self.static_index = np.arange(self.static_rows, dtype=np.int32)
        self.varying_index = np.arange(self.static_rows, rows, dtype=np.int32)
        # Velocity row i: u_P[i] - u_N[i]; one-norm rows: all of u_P and u_N.
        self.matrix = np.zeros((rows, self.columns))
        self.matrix[np.arange(n), np.arange(n)] = 1.0
        self.matrix[np.arange(n), n + np.arange(n)] = -1.0
        self.matrix[n : self.static_rows, : 2 * n] = 1.0
        # Residual rows [A_b -A_b -I_b], then linear rows [A -A 0].
        self.varying = self.matrix[self.static_rows :]
        self.varying[np.arange(residual_total), 2 * n + np.arange(residual_total)] = -1.0
        self.starts = np.arange(0, self.varying_rows * self.columns, self.columns, dtype=np.int32)
        self.indices = np.tile(self.column_index, self.varying_rows)
        self.lower = np.full(rows, -INF)
        self.upper = np.full(rows, INF)
        self.cost = np.zeros(self.columns)
        self.values = np.zeros(self.columns)
        """The vertex's column values, as the kept basis or HiGHS gives them at a step."""
        self.values_plus, self.values_minus = self.values[:n], self.values[n : 2 * n]
        self.row_weight = np.zeros(residual_total)
        """w_b of the residual cost each residual row belongs to."""
        starts = np.cumsum([0, *residual_rows]).tolist()
        self._slices = [slice(a, b) for a, b in zip(starts, starts[1:], strict=False)]
        self.offset_blocks = [self.upper[static + s.start : static + s.stop] for s in self._slices]
        """The rows of ``upper`` each residual cost's offset fills, negated (-b)."""
        self.weights: list[float] = [math.nan] * residual_count
        """The residual costs' weights ``row_weight`` and the costs of y were set from (none
        yet: NaN is no weight)."""
        self.y_costs = self.cost[2 * n :]
        self._weight_rows = [s.start if s.stop - s.start == 1 else s for s in self._slices]
        """Each residual cost's rows of ``row_weight`` and of the costs of its y: its one row's
        index (an item is set in a fraction of the time of a slice or a view's fill), or a
        slice."""
        self.col_lower = np.zeros(self.columns)
        self.col_upper = np.full(self.columns, INF)
        # Views of the buffers each step writes, made once for the shape.
        self.u_lower, self.u_upper = self.lower[:n], self.upper[:n]
        self.plus, self.minus = self.varying[:, :n], self.varying[:, n : 2 * n]
        self.stack = np.zeros((self.varying_rows, n))
        self._negated = np.zeros((self.varying_rows, n))
        filled = [i for i, count in enumerate(counts) if count]
        self.nonempty = picker(filled)
        """The matrices that hold rows, among a step's residual costs and linear rows."""
        ends = np.cumsum([0, *(counts[i] for i in filled)]).tolist()
        self.blocks = [self.stack[a:b] for a, b in zip(ends, ends[1:], strict=False)]
        """The rows of ``stack`` each of them fills."""
        self._sources: list[Array | None] = [None] * len(self.blocks)
        self._offset_sources: list[Array | None] = [None] * residual_count
        """The matrix each block and the offset each residual cost's rows were last filled from."""
        self.linear_sources: list[Array | None] = [None, None]
        """The lower and upper bounds of the linear rows were last set from, when one set fills
        them."""
        self.residual_stack = self.stack[:residual_total]
        """A_b of every residual cost, stacked: the first rows of ``stack`` (contiguous, as BLAS
        reads them without the strides of ``plus``; the same values)."""
        self.residual_upper = self.upper[static : static + residual_total]
        self.linear_lower = self.lower[static + residual_total :]
        self.linear_upper = self.upper[static + residual_total :]
        self.cost_positive, self.cost_negative = self.cost[:n], self.cost[n : 2 * n]
        self.filled = [i for i, count in enumerate(counts[residual_count:]) if count]
        """The linear row sets that hold rows (by their place among the linear ones)."""

    def fill(self, matrices: Sequence[Array], offsets: Iterable[Array]) -> None:
        """The varying rows' [A -A] from the step's ``matrices`` (each residual cost's, then
        each linear rows') and the residual rows' upper bounds -b from the residual costs'
        ``offsets``. A kept array (``wbc.laws.kept``) found where it was at the last step is
        in the buffers already: it is not copied again."""
        stack, sources, blocks = self.stack, self._sources, self.blocks
        for place, matrix in enumerate(self.nonempty(matrices)):
            if matrix is not sources[place] or id(matrix) not in KEPT:
                blocks[place][...] = sources[place] = matrix
        sources, blocks = self._offset_sources, self.offset_blocks
        for place, offset in enumerate(offsets):
            if offset is not sources[place] or id(offset) not in KEPT:
                np.negative(offset, blocks[place])
                sources[place] = offset
        self.plus[...] = stack
        np.negative(stack, self._negated)  # out given by place: less of NumPy's argument parsing
        self.minus[...] = self._negated

    def weigh(self, weights: list[float]) -> None:
        """Set ``row_weight`` and the costs of y, 2 w_b, from the weight w_b of each residual
        cost (a step calls it when they differ from ``weights``): the rows of those whose
        weight changed (a base target's ramps as the base nears it), not all."""
        row_weight, y_costs, last = self.row_weight, self.y_costs, self.weights
        for place, rows in enumerate(self._weight_rows):
            weight = weights[place]
            if weight != last[place]:
                row_weight[rows] = weight
                y_costs[rows] = 2.0 * weight
        self.weights = weights


def picker(places: list[int]) -> Callable[[Sequence], tuple]:
    """The items at ``places``, as a tuple (``operator.itemgetter`` gives one item bare)."""
    if len(places) > 1:
        return operator.itemgetter(*places)
    if places:
        place = places[0]
        return lambda items: (items[place],)
    return lambda items: ()
