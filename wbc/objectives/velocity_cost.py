"""The tie-break between optimal vertices of 5.29: a small cost on ||u||_1."""

from __future__ import annotations

import numpy as np

from wbc.objectives.base import VelocityCost
from wbc.step_context import StepContext


class LeastVelocity:
    """weight * ||u||_1: among the vertices with the best task residual, one of least speed.

    Without it (weight 0, 5.29 exactly) the simplex may return any vertex of a whole optimal
    face, often one with joints at their speed bound.
    """

    name = "least_velocity"

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
