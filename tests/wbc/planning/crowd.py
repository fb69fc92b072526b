"""A floor strewn with as many circles as an obstacles message holds, for the planners' CPU
budget (the drive planner's graph grows as the cube of the circles)."""

from __future__ import annotations

import math

import numpy as np

from messages.obstacles import MAX_CIRCLES

CHECK_GAP_S = 0.1
"""CPU time a plan may run past its budget: the work between two looks at the clock (the
way's graph looks once per disc it joins, at most 25 ms of work with 256 circles)."""

CLEAR_M = 0.8
"""No circle's centre comes this close to a point kept clear, m."""


def crowd(
    keep_clear: tuple[tuple[float, float], ...],
    count: int = MAX_CIRCLES,
    half_width: float = 5.0,
    seed: int = 0,
) -> tuple[tuple[float, float, float], ...]:
    """``count`` circles (x, y, radius), their centres uniform over a square of ``half_width``
    about the origin, radii 0.05 to 0.15 m, none within ``CLEAR_M`` of the points of
    ``keep_clear`` (the robot's start and its goal)."""
    rng = np.random.default_rng(seed)
    circles: list[tuple[float, float, float]] = []
    while len(circles) < count:
        x, y = rng.uniform(-half_width, half_width, 2)
        if all(math.hypot(x - px, y - py) >= CLEAR_M for px, py in keep_clear):
            circles.append((float(x), float(y), float(rng.uniform(0.05, 0.15))))
    return tuple(circles)
