"""Obstacles: circles in the plane of the base (section 5.5), and solids in 3-D for the arm
(``wbc.geometry.obstacles3d``); a law takes any mix of them and each constraint keeps the kind it
handles."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from wbc.geometry.obstacles3d import Cylinder, Plane, Solid


@dataclass(frozen=True)
class Circle:
    """An obstacle disc: centre (x, y) and radius, in metres, in the world frame F0."""

    x: float
    y: float
    radius: float


Obstacle = Circle | Plane | Cylinder
"""Any obstacle a law may be given."""


def split(obstacles: Iterable[Obstacle]) -> tuple[tuple[Circle, ...], tuple[Solid, ...]]:
    """The circles and the solids in 3-D among ``obstacles``, each in the given order;
    ``TypeError`` for anything else."""
    circles, solids = [], []
    for obstacle in obstacles:
        if isinstance(obstacle, Circle):
            circles.append(obstacle)
        elif isinstance(obstacle, Plane | Cylinder):
            solids.append(obstacle)
        else:
            raise TypeError(
                f"an obstacle is a Circle, Plane or Cylinder, got {type(obstacle).__name__}"
            )
    return tuple(circles), tuple(solids)


def least_clearance(bases: np.ndarray, circles: Sequence[Circle], body_radius: float) -> float:
    """min over the base positions (one (x, y) per row) and the circles of ||(x, y) - c|| - r
    - body radius, m: the least gap between the base's body and an obstacle (below 0, a
    contact); inf without circles."""
    bases = np.asarray(bases, dtype=float).reshape(-1, 2)
    gaps = [
        np.hypot(bases[:, 0] - c.x, bases[:, 1] - c.y) - c.radius - body_radius for c in circles
    ]
    return float(np.min(gaps)) if gaps else float("inf")
