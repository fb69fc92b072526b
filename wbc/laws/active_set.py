"""The constraints of the LP (5.29) that hold with equality at a step's solution, by name.

Engaged equality rows are active, and engaged inequality rows that one of their finite bounds
holds tight; a one-norm bound when 1'(u_P + u_N) reaches it; a velocity bound entry (named
``name[i]``) when u_i sits within ACTIVE_TOLERANCE of a finite, non-degenerate bound
(upper - lower > ACTIVE_TOLERANCE).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from operator import sub

import numpy as np

from wbc.laws.constraints.base import LinearRows, OneNormBound
from wbc.laws.lp_layout import picker

Array = np.ndarray
ACTIVE_TOLERANCE = 1e-7


class BoundEntries:
    """The entries of one velocity bound of n entries, split once by whether their two bounds
    were equal (such an entry is never named: its bounds are degenerate) and split again only
    when one of those is no longer equal. A fixed base's zero bounds on u_b are equal at every
    step, and u_b sits on them: the test that rules the other entries out skips them."""

    def __init__(self, name: str, n: int) -> None:
        self.names = entry_names(name, n)
        self.equal: Callable[[Sequence], tuple] | None = None
        """The entries whose bounds were equal, picked from a list of n (None: none)."""
        self.free: Callable[[Sequence], tuple] | None = None
        """The others, in order (None: all n)."""
        self.free_names = self.names

    def split(self, lows: list[float], highs: list[float]) -> None:
        """Split the entries by ``lows`` and ``highs``, a step's bounds."""
        equal = [i for i, (low, high) in enumerate(zip(lows, highs, strict=True)) if low == high]
        free = [i for i in range(len(self.names)) if i not in equal]
        self.equal = picker(equal) if equal else None
        self.free = picker(free) if equal else None
        self.free_names = self.free(self.names) if self.free else self.names


def active(
    u: Array,
    values: list[float],
    magnitudes: list[float],
    linear: Sequence[LinearRows],
    norms: Sequence[OneNormBound],
    limits: Sequence[tuple[BoundEntries, list[float], list[float]]],
) -> tuple[str, ...]:
    """Names of the constraints that hold with equality at the solution u (the module's rules).

    ``values`` and ``magnitudes`` are u_i and |u_i| as Python floats; ``limits`` each velocity
    bound's entries with its lower and upper bounds as Python floats.
    """
    # Loops, not comprehensions: a comprehension is a call of its own (Python 3.11), dearer than
    # the loop over these few rows.
    named = []
    for rows in linear:
        if rows.engaged and (rows.lower is rows.upper or _tight(rows, u)):
            named.append(rows.name)
    if norms:
        split_sum = sum(magnitudes)  # 1'(u_P + u_N), the halves split canonically
        for bound in norms:
            if split_sum >= bound.limit - ACTIVE_TOLERANCE:
                named.append(bound.name)
    for entries, lows, highs in limits:
        # On Python floats: the same IEEE arithmetic, and at 8 to 40 entries faster than NumPy.
        # An entry whose bounds are equal never counts; the others are ruled out at once when
        # each u_i lies further than the tolerance above its lower bound and below its upper
        # (an infinite bound always does; a NaN difference is skipped by min or is its result,
        # failing the test, and an entry with a NaN bound never counts).
        equal = entries.equal
        if equal is not None and equal(lows) != equal(highs):
            entries.split(lows, highs)
        free = entries.free
        if free is None:
            xs = values
        else:
            xs = free(values)
            if not xs:
                continue
            lows, highs = free(lows), free(highs)
        if (
            min(map(sub, xs, lows)) > ACTIVE_TOLERANCE
            and min(map(sub, highs, xs)) > ACTIVE_TOLERANCE
        ):
            continue
        for label, x, low, high in zip(entries.free_names, xs, lows, highs, strict=True):
            if (x - low <= ACTIVE_TOLERANCE or high - x <= ACTIVE_TOLERANCE) and (
                high - low > ACTIVE_TOLERANCE
            ):
                named.append(label)
    return tuple(named)


@functools.cache
def entry_names(name: str, n: int) -> tuple[str, ...]:
    """The names ``name[i]`` of the n entries of a velocity bound, made once."""
    return tuple(f"{name}[{i}]" for i in range(n))


def _tight(rows: LinearRows, u: Array) -> bool:
    """An equality, or an inequality one of whose rows sits on a finite bound."""
    if rows.lower is rows.upper or (
        rows.lower.shape == rows.upper.shape and not np.count_nonzero(rows.lower != rows.upper)
    ):
        return True
    value = rows.matrix @ u
    distance = np.minimum(np.abs(value - rows.lower), np.abs(rows.upper - value))
    return bool(np.count_nonzero(distance <= ACTIVE_TOLERANCE))
