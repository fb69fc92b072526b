"""The vector-field inequality for the base against each circle (Marinho, Adorno et al., T-RO
2019, arXiv 1804.11270), in place of 5.28: d' >= -eta_d d.

d = ||p - c|| - R is the distance of the base's point p, ``lookahead`` ahead of the wheel axle,
from the circle of radius R = R_obs + body radius + margin + lookahead round the obstacle's
centre c (so that the axle centre keeps R_obs + body radius + margin whatever the heading, as
in wbc.laws.constraints.obstacle_border). With n = (p - c) / ||p - c|| and
p' = (x' - d sin(phi) phi', y' + d cos(phi) phi'), the row is

    -n . p'(u) <= eta_d d,

an inequality on (x', y', phi') that every obstacle keeps at every step. u = 0 always meets it
(d >= 0), so the stability argument of section 5.8 holds, unlike 5.28's equality; it has no
switch (5.25), so it never toggles between two programs at the border; and p may approach at
most exponentially, d(t) >= d(0) exp(-eta_d t), so it never reaches the circle. Turning moves
p, so a base that faces the obstacle can steer along it.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from wbc.laws.constraints.base import LinearRows, no_rows
from wbc.laws.constraints.obstacle_border import point_velocity_row
from wbc.laws.constraints.obstacle_gains import ObstacleGains
from wbc.laws.step_context import StepContext


class VectorFieldObstacle:
    """-n . p' <= gain * d, one row per obstacle (the VFI of the module's docstring)."""

    name = "obstacle_vector_field"

    gains: ClassVar[tuple[type, ...]] = (ObstacleGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> VectorFieldObstacle | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        on = params.obstacle_mode == "vector_field"
        return (
            cls(params.obstacle_gain, params.obstacle_margin, params.obstacle_lookahead)
            if on
            else None
        )

    def __init__(self, gain: float = 2.0, margin: float = 0.05, lookahead: float = 0.1) -> None:
        if gain <= 0.0 or margin < 0.0 or lookahead < 0.0:
            raise ValueError("vector-field obstacle needs gain > 0, margin >= 0 and lookahead >= 0")
        self.gain, self.margin, self.lookahead = gain, margin, lookahead

    def rows(self, context: StepContext) -> LinearRows:
        count, dof = len(context.obstacles), context.robot.dof
        if count == 0:
            return no_rows(self.name, dof)
        matrix, upper = np.zeros((count, dof)), np.zeros(count)
        phi = float(context.q[2])
        px = float(context.q[0]) + self.lookahead * math.cos(phi)
        py = float(context.q[1]) + self.lookahead * math.sin(phi)
        for row, obstacle in enumerate(context.obstacles):
            dx, dy = px - obstacle.x, py - obstacle.y
            norm = math.hypot(dx, dy) or 1.0
            radius = obstacle.radius + context.robot.base.body_radius + self.margin
            distance = norm - radius - self.lookahead
            matrix[row] = point_velocity_row(-dx / norm, -dy / norm, phi, self.lookahead, dof)
            upper[row] = self.gain * max(distance, 0.0)
        return LinearRows(self.name, matrix, np.full(count, -np.inf), upper, engaged=count > 0)
