"""What every control law returns: the whole-body velocity and its diagnostics."""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, NamedTuple, Protocol

import numpy as np

if TYPE_CHECKING:
    from wbc.geometry.obstacles import Obstacle
    from wbc.task import Task

Array = np.ndarray

ZERO_THRESHOLD = 1e-9
"""|u_i| above this counts as a nonzero entry of u."""
PRACTICAL_THRESHOLD = 0.01
"""Upsilon of section 6.2.1: the smallest velocity a motor acts on (rad/s or m/s)."""


class LawOutput(NamedTuple):
    """u = [x', y', phi', q_1'..q_n'] (the base's velocities, then each arm joint's) and how
    it was obtained (a named tuple: built at every step in a fraction of the time of a frozen
    dataclass)."""

    u: Array
    status: str
    objective: float | None
    nonzero: int
    practical_nonzero: int
    active_constraints: tuple[str, ...]
    solve_time_s: float
    error_norm: float

    @property
    def ok(self) -> bool:
        return self.status == "optimal"


class Law(Protocol):
    """What every control law offers: ``LPLaw``, ``CascadeLaw``, ``PseudoinverseLaw``."""

    params: Any

    def step(
        self, q: Array, task: Task, dt: float, obstacles: Sequence[Obstacle] = ()
    ) -> LawOutput: ...

    def set_params(self, params: Any) -> None: ...

    def reset(self) -> None: ...

    def stopped(self) -> None:
        """The robot was told to stand still without this law's step (a held controller):
        its next step starts from rest."""


def entry_mask(u: Array, practical: bool = False) -> int:
    """Bit i set where u_i counts as nonzero: |u_i| > ZERO_THRESHOLD, or, ``practical``, where
    |u_i| >= PRACTICAL_THRESHOLD (a motor acts on it)."""
    magnitude = np.abs(u)
    above = magnitude >= PRACTICAL_THRESHOLD if practical else magnitude > ZERO_THRESHOLD
    return sum(1 << int(i) for i in np.flatnonzero(above))


def summarise(
    u: Array,
    status: str,
    objective: float | None,
    active: tuple[str, ...],
    error: Array,
    start: float,
    owned: bool = False,
    magnitudes: list[float] | None = None,
) -> LawOutput:
    """Freeze u and count its nonzero entries (section 5.7) and practical ones (6.2.1).

    ``owned``: u is a new float array no one else holds (the LP's), frozen in place, not copied.
    ``magnitudes``: |u_i| as Python floats, where the law has them (the LP's).
    """
    if not owned:
        u = np.array(u, dtype=float)
    u.setflags(write=False)
    if magnitudes is None:
        magnitudes = list(map(abs, u.tolist()))
    # Counted on Python floats: the same comparisons, in a fraction of NumPy's time at these
    # sizes; a practical entry is a nonzero one (PRACTICAL_THRESHOLD > ZERO_THRESHOLD). A loop,
    # not a comprehension: one is a call of its own (Python 3.11), dearer at 8 to 40 entries.
    nonzero = practical = 0
    for magnitude in magnitudes:
        if magnitude > ZERO_THRESHOLD:
            nonzero += 1
            if magnitude >= PRACTICAL_THRESHOLD:
                practical += 1
    # Built by tuple.__new__: the same value, without the named tuple's own __new__'s frame.
    return tuple.__new__(
        LawOutput,
        (
            u,
            status,
            objective,
            nonzero,
            practical,
            active,
            time.perf_counter() - start,
            math.sqrt(error.dot(error)),  # ndarray.dot: @'s sum, in half the time
        ),
    )
