"""The border-following obstacle constraint (5.21-5.28, switched by 5.25)."""

from __future__ import annotations

import math

import numpy as np

from wbc.constraints.base import LinearRows
from wbc.step_context import StepContext


class BorderObstacle:
    """beta J_c p' = beta lambda alpha, one row per obstacle (5.27, 5.28), on a point p of the base.

    p = (x + d cos phi, y + d sin phi) lies ``lookahead`` d ahead of the wheel axle (the point
    of appendix B). f = R^2 - ||p - c||^2 (5.21), alpha = -f, J_c = -2 (p - c)' (5.23), and
    p' = (x' - d sin(phi) phi', y' + d cos(phi) phi'), so the row acts on (x', y', phi').
    R = R_obs + body radius + margin + d keeps the axle centre at least
    R_obs + body radius + margin from c whatever the heading.

    The switch beta (5.25) is 1 when p is inside the extended disc (f > 0) and the obstacle
    lies between it and the goal, h = ||q_d - p|| - ||q_d - c|| > 0 (q_d the goal's projection
    on the plane); else 0. Engaged, the row sets the radial velocity of p so that
    alpha' = -lambda alpha and leaves its tangential velocity free.

    With d = 0 this is 5.27 on the axle centre exactly. For a differential-drive base that
    pins the forward speed (x', y' are v times the heading) and leaves phi' no effect on the
    row, so a base facing the obstacle has no reason to turn and stops at the border; d > 0
    lets the row be met by turning, and the base steers along the border.
    """

    name = "obstacle_border"

    def __init__(self, gain: float = 2.0, margin: float = 0.05, lookahead: float = 0.1) -> None:
        if gain <= 0.0 or margin < 0.0 or lookahead < 0.0:
            raise ValueError("border obstacle needs gain > 0, margin >= 0 and lookahead >= 0")
        self.gain = gain
        self.margin = margin
        self.lookahead = lookahead

    def rows(self, context: StepContext) -> LinearRows:
        count = len(context.obstacles)
        matrix = np.zeros((count, context.robot.dof))
        if count == 0:
            return LinearRows(self.name, matrix, np.zeros(0), np.zeros(0), engaged=False)
        rhs = np.zeros(count)
        d = self.lookahead
        phi = float(context.q[2])
        cos, sin = math.cos(phi), math.sin(phi)
        px, py = float(context.q[0]) + d * cos, float(context.q[1]) + d * sin
        gx, gy = float(context.goal_xy[0]), float(context.goal_xy[1])
        for row, obstacle in enumerate(context.obstacles):
            dx, dy = px - obstacle.x, py - obstacle.y
            radius = obstacle.radius + context.robot.base.body_radius + self.margin + d
            f = radius * radius - (dx * dx + dy * dy)
            h = math.hypot(gx - px, gy - py) - math.hypot(gx - obstacle.x, gy - obstacle.y)
            if f > 0.0 and h > 0.0:
                matrix[row, 0], matrix[row, 1] = -2.0 * dx, -2.0 * dy
                matrix[row, 2] = 2.0 * d * (dx * sin - dy * cos)
                rhs[row] = self.gain * -f
        return LinearRows(self.name, matrix, rhs, rhs, engaged=bool(np.any(matrix)))
