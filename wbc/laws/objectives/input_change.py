"""Smoother inputs (future work 1 of 7.2): a price on how u changes from one step to the next.

The LP's inputs are abrupt: from rest to full speed at its first step, and from one vertex of
5.29 to another whenever the optimal basis changes. With p = u_prev the u of the previous step
(``StepContext.previous_u``) and w the weight, this term adds to the objective either

* ``change``: w ||u - p||_1, every change priced (the form future work 1 suggests), or
* ``speeding_up``: w sum_i dist(u_i, [min(p_i - s_i, 0), max(p_i + s_i, 0)]), s_i = v_i dt / T,
  v_i the speed bound of u_i (5.15) and T the ramp: a change is free while an entry slows down
  towards 0, or speeds up by at most s_i a step (its full speed from rest in T), and costs w
  per unit beyond.

Both are one residual cost of 2n rows, w/2 (|u - l| + |u - h|) = w dist(u, [l, h]) +
w (h - l) / 2 (l = h = p for ``change``), so the program stays an LP; the constant does not
move the optimum.

``change`` does not keep the LP parsimonious or its goals reached: |u_i - p_i| has a kink at
p_i, so an entry may stay at its last value at a vertex without a basic column, and entries
accumulate (6 nonzero while moving on the position task at w 0.01, where the LP uses 4); and it
prices starting an entry from rest at w per unit, as a 1-norm velocity cost does, which stalls
the pose task where J is poorly conditioned (at w 0.05 the goal of 6.2.1 is not reached).
``speeding_up`` keeps u = 0 and every slower u free, so stopping is never priced and a vertex
that drops entries costs nothing; it prices the jump up, as a bound on acceleration would,
without ever making the program infeasible where another row excludes u = 0 (a joint beyond
its margin, an obstacle's border); at w 3 it holds as a bound at every step of 6.2.1. At w 0.5
and T 0.2 s (deploy/sim_smooth.yaml) it keeps the share of `parsimony bench`'s 'ahead' goals
reached and the nonzero entries; T 0.4 s and longer lost 2 to 5 of those 100 goals. It is off
by default (README, "Smoother inputs": metric 4 falls, metric 3 does not).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Literal, get_args

import numpy as np

from wbc.laws.gains import gain
from wbc.laws.objectives.base import ResidualCost
from wbc.laws.step_context import StepContext

InputChangeForm = Literal["change", "speeding_up"]
"""What the term prices: every change of u, or speeding up faster than the ramp."""


@dataclass(frozen=True)
class InputChangeGains:
    input_change: float = gain(
        0.0,
        low=0.0,
        high=10.0,
        doc="w of the input change term, per unit of u (wbc.laws.objectives.input_change; 0: off)",
    )
    input_change_form: InputChangeForm = gain(
        "speeding_up",
        doc="what it prices: every change of u (change: w ||u - u_prev||_1), or "
        "speeding up faster than the ramp (speeding_up)",
    )
    input_change_ramp: float = gain(
        0.2,
        low=1e-3,
        high=100.0,
        doc="T of speeding_up: the free ramp takes an entry from rest to its speed bound in T, s",
    )


class InputChange:
    """w dist(u, [l, h]) entry by entry, with [l, h] = [p, p] (``change``) or the band of
    ``speeding_up`` about p = u_prev; idle (weight 0) without a previous u."""

    name = "input_change"

    gains: ClassVar[tuple[type, ...]] = (InputChangeGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> InputChange | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        on = params.input_change > 0.0
        return (
            cls(params.input_change, params.input_change_form, params.input_change_ramp)
            if on
            else None
        )

    def __init__(
        self, weight: float, form: InputChangeForm = "speeding_up", ramp_s: float = 0.2
    ) -> None:
        if not (weight >= 0.0 and ramp_s > 0.0 and form in get_args(InputChangeForm)):
            raise ValueError(
                f"input change needs weight >= 0, ramp_s > 0 and a form in "
                f"{get_args(InputChangeForm)}"
            )
        self.weight, self.form, self.ramp_s = weight, form, ramp_s
        self._matrix: np.ndarray | None = None

    def band(self, context: StepContext) -> tuple[np.ndarray, np.ndarray]:
        """[l, h]: where a change of u is free, entry by entry."""
        previous = np.asarray(context.previous_u, dtype=float)
        if self.form == "change":
            return previous, previous
        step = context.robot.velocity_max * (context.dt / self.ramp_s)
        return np.minimum(previous - step, 0.0), np.maximum(previous + step, 0.0)

    def cost(self, context: StepContext) -> ResidualCost:
        n = context.robot.dof
        if self._matrix is None or self._matrix.shape[1] != n:
            self._matrix = np.vstack((np.eye(n), np.eye(n)))
            self._matrix.flags.writeable = False
        if context.previous_u is None:
            return ResidualCost(self.name, self._matrix, np.zeros(2 * n), 0.0)
        low, high = self.band(context)
        return ResidualCost(
            self.name, self._matrix, -np.concatenate((low, high)), 0.5 * self.weight
        )

    def reset(self) -> None:
        """Stateless: the previous u is the law's (``StepContext.previous_u``)."""
