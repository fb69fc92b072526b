"""The tie-break between optimal vertices of 5.29: a small cost on ||u||_1."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc.laws.gains import gain
from wbc.laws.objectives.base import VelocityCost
from wbc.laws.step_context import StepContext


@dataclass(frozen=True)
class VelocityCostGains:
    velocity_cost: float = gain(
        1e-3,
        low=0.0,
        high=1.0,
        doc="w of w ||u||_1, the tie-break between optimal vertices; "
        "0 with the other weights solves 5.29 exactly "
        "(wbc.laws.objectives.velocity_cost)",
    )


class LeastVelocity:
    """weight * ||u||_1: among the vertices with the best task residual, one of least speed.

    Without it (weight 0, 5.29 exactly) the simplex may return any vertex of a whole optimal
    face, often one with joints at their speed bound.
    """

    name = "least_velocity"

    gains: ClassVar[tuple[type, ...]] = (VelocityCostGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> LeastVelocity | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        return cls(params.velocity_cost) if params.velocity_cost > 0.0 else None

    def __init__(self, weight: float = 1e-3) -> None:
        if not weight >= 0.0:
            raise ValueError(f"least velocity weight must be >= 0, got {weight}")
        self.weight = weight
        self._cost: VelocityCost | None = None

    def cost(self, context: StepContext) -> VelocityCost:
        if self._cost is None or self._cost.weights.size != context.robot.dof:
            weights = np.full(context.robot.dof, self.weight)
            weights.flags.writeable = False
            self._cost = VelocityCost(self.name, weights)
        return self._cost

    def reset(self) -> None:
        """Stateless."""
