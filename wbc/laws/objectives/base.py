"""What a term of the LP's objective returns: a weighted 1-norm, so the program stays an LP.

A term is a small object with a ``name`` and ``cost(context)``; it returns one of two kinds,
and the LP builder only adds them up:
``ResidualCost`` (w ||A u + b||_1: the task itself, with A = J and b = eta e, or a secondary
goal such as keeping the waist centred) or ``VelocityCost`` (sum_i w_i |u_i|, a cost on the
split columns u_P + u_N, which may differ between the two directions of an entry). Weights
are >= 0, so the sum stays convex and its minimiser a vertex. Both are named tuples, built at
every step in a fraction of the time of a frozen dataclass.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np

from wbc.laws.kept import kept, zeros
from wbc.laws.step_context import StepContext

Array = np.ndarray


class ResidualCost(NamedTuple):
    """weight * ||matrix u + offset||_1, one residual per row of ``matrix``."""

    name: str
    matrix: Array
    offset: Array
    weight: float = 1.0


@functools.cache
def unit_row(dof: int, column: int) -> Array:
    """The read-only row (1, dof) that picks entry ``column`` of u."""
    row = np.zeros((1, dof))
    row[0, column] = 1.0
    return kept(row)


@functools.cache
def no_cost(name: str, dof: int) -> ResidualCost:
    """A term that asks nothing (weight 0) of u of ``dof`` entries, holding its place among
    the rows: one read-only value per name and size."""
    return ResidualCost(name, zeros(1, dof), zeros(1), 0.0)


class VelocityCost(NamedTuple):
    """sum_i weights_i max(u_i, 0) + negative_i max(-u_i, 0): a cost on the split columns u_P
    and u_N, the same both ways (sum_i weights_i |u_i|) unless ``negative`` is given."""

    name: str
    weights: Array
    negative: Array | None = None

    @property
    def negative_weights(self) -> Array:
        return self.weights if self.negative is None else self.negative


Cost = ResidualCost | VelocityCost


class ObjectiveTerm(Protocol):
    name: str

    def cost(self, context: StepContext) -> Cost: ...

    def reset(self) -> None:
        """Forget what earlier steps left (a new task begins)."""


@dataclass
class Latch:
    """On once |x| exceeds ``on``, off again once it falls below ``off`` (< on): a term that
    acts in bursts, not at the edge of a band, where it would act at every step."""

    on: float
    off: float
    engaged: bool = False

    def __post_init__(self) -> None:
        if not 0.0 <= self.off < self.on:
            raise ValueError(f"a latch needs 0 <= off < on, got off {self.off}, on {self.on}")

    def update(self, x: float) -> bool:
        if abs(x) > self.on:
            self.engaged = True
        elif abs(x) < self.off:
            self.engaged = False
        return self.engaged
