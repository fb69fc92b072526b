"""What a constraint of the LP (5.29) returns: rows on the whole-body velocity u.

A constraint is a small object with a ``name`` and ``rows(context)``; it returns one of three
kinds of rows on the whole-body velocity u, and the LP builder only stacks them:
``LinearRows`` (lower <= A u <= upper, an equality where lower == upper),
``VelocityBounds`` (lower <= u <= upper, entry by entry) or
``OneNormBound`` (||u||_1 <= limit, written 1'u_P + 1'u_N <= limit on the split u = u_P - u_N).
Each is a named tuple: built at every step, in a fraction of the time of a frozen dataclass.
"""

from __future__ import annotations

import functools
from typing import NamedTuple, Protocol

import numpy as np

from wbc.laws.kept import zeros
from wbc.laws.step_context import StepContext

Array = np.ndarray


class LinearRows(NamedTuple):
    """lower <= matrix u <= upper; ``engaged`` is False when the rows are switched off."""

    name: str
    matrix: Array
    lower: Array
    upper: Array
    engaged: bool = True


@functools.cache
def no_rows(name: str, dof: int) -> LinearRows:
    """No row (switched off), for u of ``dof`` entries: one read-only value per name and size."""
    return LinearRows(name, zeros(0, dof), zeros(0), zeros(0), engaged=False)


class VelocityBounds(NamedTuple):
    """lower <= u <= upper, one pair per entry of u; ``ordered`` where lower <= upper holds by
    construction (bounds made by an entry's minimum and maximum), so the LP need not test it."""

    name: str
    lower: Array
    upper: Array
    ordered: bool = False


class OneNormBound(NamedTuple):
    """||u||_1 <= limit."""

    name: str
    limit: float


Rows = LinearRows | VelocityBounds | OneNormBound


class Constraint(Protocol):
    name: str

    def rows(self, context: StepContext) -> Rows: ...
