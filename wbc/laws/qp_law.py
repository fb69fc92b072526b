"""The same robot, rows and terms as the LP, as a quadratic program (future work 5 of chapter 7:
"a comparison between the linear programming and nonlinear programming approaches").

    min  ||J u + eta e||_2^2 + sum_b w_b^2 ||A_b u + b_b||_2^2 + c'|u| + lambda ||u||_2^2
    s.t. the rows of 5.29: velocity bounds (5.15), ||u||_1 <= beta ||e'||_1 (5.10), the
         nonholonomic equality (5.12) and the obstacle rows, as the LP's constraints give them

Each residual term of the LP's objective is squared here (the task first, w = 1), each velocity
term stays linear. As in the LP, u = u_P - u_N with u_P, u_N >= 0, so the 1-norm rows stay
linear; the damping lambda is put on both halves (lambda (||u_P||^2 + ||u_N||^2), which equals
lambda ||u||^2 at the optimum, where one of each pair is 0) and makes the Hessian positive
definite. DAQP (a dual active-set solver for small dense QPs) solves it, warm-started from the
last step's active set; HiGHS's QP solver, tried first, took 35 ms a step at this size.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import daqp
import numpy as np

from wbc.geometry.obstacles import Obstacle
from wbc.laws.constraints.base import Constraint, LinearRows, OneNormBound, VelocityBounds
from wbc.laws.gains import composed, gain
from wbc.laws.law_output import LawOutput, summarise
from wbc.laws.lp_law import (
    CONSTRAINTS,
    OBJECTIVES,
    TaskGains,
    default_constraints,
    default_objectives,
    program,
)
from wbc.laws.objectives.base import ObjectiveTerm, ResidualCost, VelocityCost
from wbc.robot import MobileManipulator
from wbc.task import Task

Array = np.ndarray
INF = 1e30
"""DAQP's infinite bound."""


@dataclass(frozen=True)
class DampingGains:
    damping: float = gain(
        1e-3, low=1e-9, high=10.0, doc="lambda of lambda ||u||^2: keeps the QP strictly convex"
    )


QP_DEFAULTS = {"velocity_cost": 0.0, "waist_hold": 0.0, "input_change": 0.0}
"""The LP's 1-norm velocity terms are off in the QP: beside a squared task residual, a constant
price on |u| is a dead zone (a lasso), where the task's pull, eta e, no longer beats it; on the
pose goal of 6.2.1 the QP with them stalls at ||e|| = 0.006 (0.001 without). So is the input
change term (wbc.laws.objectives.input_change): its free band is a 1-norm construct, and squared its
two rows pull u towards the middle of the band; its ``change`` form squared,
(w^2 / 2) ||u - u_prev||^2, is the usual rate penalty of a QP, there to be turned on."""
QPParams = composed(
    "QPParams",
    "Gains of the QP law: the LP's, each declared by the term that reads it, and the damping.",
    [TaskGains, DampingGains, *(part for term in CONSTRAINTS + OBJECTIVES for part in term.gains)],
    __name__,
    QP_DEFAULTS,
)


@dataclass
class QPLaw:
    """u = argmin of the quadratic program above, solved by DAQP (``WarmStartedQP``).

    ``step`` never raises for a solver failure: it returns u = 0 with DAQP's exit status, or
    ``non-finite`` (a u that is not finite is never ``optimal``). The error rate e' is measured
    as the LP measures it (the rows are the LP's), and the previous u is kept as the LP keeps
    it.
    """

    robot: MobileManipulator
    params: QPParams = field(default_factory=QPParams)
    _last: tuple[Task, Array] | None = field(default=None, init=False, repr=False)
    _constraints: list[Constraint] | None = field(default=None, init=False, repr=False)
    _objectives: list[ObjectiveTerm] | None = field(default=None, init=False, repr=False)
    _qp: WarmStartedQP = field(default_factory=lambda: WarmStartedQP(), init=False, repr=False)
    _previous_u: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.stopped()

    def set_params(self, params: QPParams) -> None:
        self.params, self._constraints, self._objectives = params, None, None

    def reset(self) -> None:
        self._last = None
        self._qp.reset()
        for term in self._objectives or ():
            term.reset()

    def stopped(self) -> None:
        """The robot was told to stand still: u_prev = 0."""
        self._previous_u = np.zeros(self.robot.dof)

    def step(
        self, q: Array, task: Task, dt: float, obstacles: Sequence[Obstacle] = ()
    ) -> LawOutput:
        start = time.perf_counter()
        if self._constraints is None:
            self._constraints = default_constraints(self.params)
            self._objectives = default_objectives(self.params)
        costs, rows, error, self._last = program(
            self.robot,
            q,
            task,
            dt,
            obstacles,
            self.params.eta,
            self._last,
            self._constraints,
            self._objectives,
            self._previous_u,
        )
        u, status, objective = self._qp.solve(self.robot.dof, costs, rows, self.params.damping)
        output = summarise(u, status, objective, (), error, start)
        self._previous_u = output.u
        return output


@dataclass
class WarmStartedQP:
    """The QP over g = [u_P, u_N] >= 0, solved by DAQP from the last step's active set:
    min c'g + g'H g / 2 with H = 2 (sum_b w_b^2 S'A_b'A_b S + lambda I), c = 2 sum_b w_b^2
    S'A_b'b_b plus the velocity costs, S = [I -I]."""

    _active: Array | None = None

    def reset(self) -> None:
        self._active = None

    def solve(
        self, n: int, costs: list, rows: list, damping: float
    ) -> tuple[Array, str, float | None]:
        """u, the status and the objective: u = 0 with the status ``non-finite`` where the
        program's numbers overflow (a configuration of 1e300 m) or DAQP's solution is not
        finite; never ``optimal`` with a u that is not."""
        split = np.hstack((np.eye(n), -np.eye(n)))
        with np.errstate(over="ignore", invalid="ignore"):  # tested just below
            hessian, linear = _objective(split, costs, damping)
        if not (np.isfinite(hessian).all() and np.isfinite(linear).all()):
            return np.zeros(n), NON_FINITE, None
        matrix, lower, upper = [split], [np.full(n, -INF)], [np.full(n, INF)]
        for row in rows:
            if isinstance(row, VelocityBounds):
                np.maximum(lower[0], row.lower, out=lower[0])
                np.minimum(upper[0], row.upper, out=upper[0])
            elif isinstance(row, OneNormBound):
                matrix.append(np.ones((1, 2 * n)))
                lower.append(np.array([-INF]))
                upper.append(np.array([row.limit]))
            elif isinstance(row, LinearRows):
                matrix.append(row.matrix @ split)
                lower.append(np.asarray(row.lower, dtype=float))
                upper.append(np.asarray(row.upper, dtype=float))
        if (lower[0] > upper[0]).any():
            return np.zeros(n), "infeasible", None
        a = np.vstack(matrix)
        # The first 2n bounds are g >= 0 (simple bounds), then the rows.
        low = np.concatenate((np.zeros(2 * n), *lower))
        high = np.concatenate((np.full(2 * n, INF), *upper))
        equal = np.concatenate(
            (np.zeros(2 * n, dtype=bool), *(lo == hi for lo, hi in zip(lower, upper, strict=True)))
        )
        sense = np.where(equal, EQUALITY, 0).astype(np.intc)
        if self._active is not None and self._active.shape == sense.shape:
            sense |= np.where(equal, 0, self._active).astype(np.intc)
        g, objective, flag, info = daqp.solve(hessian, linear, a, high, low, sense)
        if flag < 1:
            self._active = None
            return np.zeros(n), EXIT_FLAGS.get(flag, f"daqp exit {flag}"), None
        g = np.asarray(g)
        if not np.isfinite(g).all():
            self._active = None
            return np.zeros(n), NON_FINITE, None
        self._active = np.where(np.abs(np.asarray(info["lam"])) > 0, ACTIVE, 0)
        # An entry whose bounds meet (a fixed base's u_b) is that bound exactly, not DAQP's
        # 1e-15 round-off beside it: a zero the counts of nonzero entries see as zero.
        u = g[:n] - g[n:]
        pinned = lower[0] == upper[0]
        u[pinned] = lower[0][pinned]
        return u, "optimal", float(objective)


def _objective(split: Array, costs: list, damping: float) -> tuple[Array, Array]:
    """H and c of the QP over g = [u_P, u_N] (see ``WarmStartedQP``)."""
    size = split.shape[1]
    hessian = 2.0 * damping * np.eye(size)
    linear = np.zeros(size)
    for cost in costs:
        if isinstance(cost, ResidualCost):
            a = cost.matrix @ split
            weight = cost.weight**2
            hessian += 2.0 * weight * (a.T @ a)
            linear += 2.0 * weight * (a.T @ cost.offset)
        elif isinstance(cost, VelocityCost):
            linear += np.concatenate((cost.weights, cost.negative_weights))
    return hessian, linear


NON_FINITE = "non-finite"
"""The status of a step whose program or solution is not finite."""
EQUALITY, ACTIVE = 5, 1
"""DAQP's senses: an equality row, and an inequality taken as active (a warm start)."""
EXIT_FLAGS = {
    -1: "infeasible",
    -2: "cycling",
    -3: "unbounded",
    -4: "iteration limit",
    -5: "nonconvex",
    -6: "initial active set infeasible",
}
"""DAQP's exit flags below 1, as statuses."""
