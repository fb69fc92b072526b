"""The border-following obstacle constraint (5.21-5.28, switched by 5.25)."""

from __future__ import annotations

import math

import numpy as np

from wbc.constraints.base import LinearRows, StepContext


class BorderObstacle:
    """beta J_c u_xy = beta lambda alpha, one row per obstacle (5.27, 5.28).

    f = R^2 - ||q_xy - c||^2 (5.21) with R = R_obs + body radius + margin; alpha = -f;
    J_c = -2 (q_xy - c)' (5.23). The switch beta (5.25) is 1 when the base is inside the
    extended disc (f > 0) and the obstacle lies between it and the goal,
    h = ||q_d - q_xy|| - ||q_d - c|| > 0, with q_d the goal's projection on the plane; else 0.
    Engaged, the row fixes the radial velocity so that alpha' = -lambda alpha and leaves the
    tangential one free: the base slides back to the border and along it.
    """

    name = "obstacle_border"

    def __init__(self, gain: float = 2.0, margin: float = 0.05) -> None:
        if gain <= 0.0 or margin < 0.0:
            raise ValueError("border obstacle constraint needs gain > 0 and margin >= 0")
        self.gain = gain
        self.margin = margin

    def rows(self, context: StepContext) -> LinearRows:
        count = len(context.obstacles)
        matrix = np.zeros((count, context.robot.dof))
        rhs = np.zeros(count)
        x, y = float(context.q[0]), float(context.q[1])
        gx, gy = float(context.goal_xy[0]), float(context.goal_xy[1])
        for row, obstacle in enumerate(context.obstacles):
            dx, dy = x - obstacle.x, y - obstacle.y
            radius = obstacle.radius + context.robot.base.body_radius + self.margin
            f = radius * radius - (dx * dx + dy * dy)
            h = math.hypot(gx - x, gy - y) - math.hypot(gx - obstacle.x, gy - obstacle.y)
            if f > 0.0 and h > 0.0:
                matrix[row, 0], matrix[row, 1] = -2.0 * dx, -2.0 * dy
                rhs[row] = self.gain * -f
        return LinearRows(self.name, matrix, rhs, rhs, engaged=bool(np.any(matrix)))
