"""Obstacles: circles in the plane of the base (section 5.5), and solids in 3-D for the arm
(``wbc.obstacles3d``); a law takes any mix of them and each constraint keeps the kind it
handles."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from wbc.obstacles3d import Cylinder, Plane, Solid


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
            raise TypeError(f"an obstacle is a Circle, Plane or Cylinder, got "
                            f"{type(obstacle).__name__}")  # fmt: skip
    return tuple(circles), tuple(solids)
