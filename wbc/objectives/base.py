"""What a term of the LP's objective returns: a weighted 1-norm, so the program stays an LP.

A term is a small object with a ``name`` and ``cost(context)``; it returns one of two kinds,
and the LP builder only adds them up:
``ResidualCost`` (w ||A u + b||_1: the task itself, with A = J and b = eta e, or a secondary
goal such as keeping the waist centred) or ``VelocityCost`` (sum_i w_i |u_i|, a cost on the
split columns u_P + u_N). Weights are >= 0, so the sum stays convex and its minimiser a vertex.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from wbc.step_context import StepContext

Array = np.ndarray


@dataclass(frozen=True)
class ResidualCost:
    """weight * ||matrix u + offset||_1, one residual per row of ``matrix``."""

    name: str
    matrix: Array
    offset: Array
    weight: float = 1.0


@dataclass(frozen=True)
class VelocityCost:
    """sum_i weights_i |u_i|."""

    name: str
    weights: Array


Cost = ResidualCost | VelocityCost


class ObjectiveTerm(Protocol):
    name: str

    def cost(self, context: StepContext) -> Cost: ...
