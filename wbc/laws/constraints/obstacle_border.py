"""The border-following obstacle constraint (5.21-5.28, switched by 5.25)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc.geometry.obstacles import Circle
from wbc.laws.constraints.base import LinearRows
from wbc.laws.constraints.obstacle_gains import ObstacleGains
from wbc.laws.step_context import StepContext

Array = np.ndarray


@dataclass(frozen=True)
class Border:
    """Where the base's point p stands against one obstacle: p - c, f = R^2 - ||p - c||^2
    (5.21), and whether 5.25 engages the border (f > 0, the obstacle between p and the goal)."""

    dx: float
    dy: float
    f: float
    h: float
    """5.25's h: > 0 while the obstacle lies between p and the goal."""
    engaged: bool


def border(context: StepContext, obstacle: Circle, margin: float, lookahead: float) -> Border:
    """The border of ``obstacle`` for the point ``lookahead`` ahead of the wheel axle, its
    radius R = R_obs + body radius + ``margin`` + ``lookahead``."""
    phi = float(context.q[2])
    px = float(context.q[0]) + lookahead * math.cos(phi)
    py = float(context.q[1]) + lookahead * math.sin(phi)
    gx, gy = float(context.goal_xy[0]), float(context.goal_xy[1])
    dx, dy = px - obstacle.x, py - obstacle.y
    radius = obstacle.radius + context.robot.base.body_radius + margin + lookahead
    f = radius * radius - (dx * dx + dy * dy)
    h = math.hypot(gx - px, gy - py) - math.hypot(gx - obstacle.x, gy - obstacle.y)
    return Border(dx, dy, f, h, f > 0.0 and h > 0.0)


def point_velocity_row(dx: float, dy: float, phi: float, lookahead: float, dof: int) -> Array:
    """The row a on u with a u = (dx, dy) . p', p' = (x' - d sin(phi) phi', y' + d cos(phi)
    phi') the velocity of the point d ahead of the axle."""
    row = np.zeros(dof)
    row[0], row[1] = dx, dy
    row[2] = lookahead * (dy * math.cos(phi) - dx * math.sin(phi))
    return row


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

    gains: ClassVar[tuple[type, ...]] = (ObstacleGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> BorderObstacle | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        on = params.obstacle_mode == "border"
        return (
            cls(params.obstacle_gain, params.obstacle_margin, params.obstacle_lookahead)
            if on
            else None
        )

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
        phi = float(context.q[2])
        for row, obstacle in enumerate(context.obstacles):
            at = border(context, obstacle, self.margin, self.lookahead)
            if at.engaged:
                matrix[row] = point_velocity_row(
                    -2.0 * at.dx, -2.0 * at.dy, phi, self.lookahead, context.robot.dof
                )
                rhs[row] = self.gain * -at.f
        return LinearRows(self.name, matrix, rhs, rhs, engaged=bool(np.any(matrix)))
