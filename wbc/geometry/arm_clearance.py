"""How far each collision part of the robot is from each obstacle in 3-D, and the penetrations
that begin: what the simulator counts and the judge reports, from the kinematics alone.

The clearance of a part from a solid is min over the part's points of (the exact signed
distance of the point from the solid, ``wbc.geometry.obstacles3d``) - radius: a sphere's centre, or
a capsule's axis sampled every ``SPACING`` from end to end (the sampled minimum exceeds the
capsule's by at most SPACING^2 / (8 rho) for a flat face: 0.5 mm at rho = 25 mm). Negative is a
penetration, its depth.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from wbc.collision_model import point_positions
from wbc.geometry.obstacles3d import Solid
from wbc.robot import MobileManipulator

Array = np.ndarray

SPACING = 0.01
"""Distance between the samples of a segment's axis, m."""


def part_clearances(robot: MobileManipulator, q: Array, solids: Sequence[Solid]) -> Array:
    """(parts, solids) clearances, m: the points of ``robot.collision``, then its segments."""
    model = robot.collision
    points = point_positions(robot.frames(q), model)
    clearances = np.empty((len(model.names), len(solids)))
    if not solids:
        return clearances
    for i, point in enumerate(model.points):
        clearances[i] = [solid.clearance(points[i])[0] - point.radius for solid in solids]
    for j, segment in enumerate(model.segments):
        start, end = points[segment.start], points[segment.end]
        count = max(2, math.ceil(float(np.linalg.norm(end - start)) / SPACING) + 1)
        samples = start + np.linspace(0.0, 1.0, count)[:, None] * (end - start)
        row = len(model.points) + j
        clearances[row] = [solid.clearance(samples).min() - segment.radius for solid in solids]
    return clearances


@dataclass
class PenetrationCount:
    """Counts each (part, solid) pair's penetrations as they begin, as pymunk counts a contact
    when two shapes begin to touch."""

    count: int = 0
    inside: Array = field(default_factory=lambda: np.zeros((0, 0), dtype=bool))

    def update(self, clearances: Array) -> None:
        """Take the clearances of a step: each pair below 0 that was not is one more."""
        now = clearances < 0.0
        before = self.inside if self.inside.shape == now.shape else np.zeros_like(now)
        self.count += int(np.count_nonzero(now & ~before))
        self.inside = now

    @property
    def penetrating(self) -> bool:
        """Whether a part penetrates a solid now."""
        return bool(self.inside.any())
