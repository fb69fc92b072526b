"""The conservative obstacle constraint (5.19): the base slows to a stop before an obstacle."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from wbc.laws.constraints.base import VelocityBounds
from wbc.laws.constraints.obstacle_gains import ObstacleGains
from wbc.laws.step_context import StepContext


class ConservativeObstacle:
    """-d <= x', y' <= d, with d = gain * (clearance between base and the nearest obstacle).

    The clearance is ||q_xy - c|| - (R_obs + body radius + margin), floored at 0; ``gain`` is
    in 1/s. The base velocity falls to zero as the clearance does, in every direction, so the
    robot stops before the disc and cannot go round it.
    """

    name = "obstacle_conservative"

    gains: ClassVar[tuple[type, ...]] = (ObstacleGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> ConservativeObstacle | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        on = params.obstacle_mode == "conservative"
        return cls(params.obstacle_gain, params.obstacle_margin) if on else None

    def __init__(self, gain: float = 1.0, margin: float = 0.05) -> None:
        if gain <= 0.0 or margin < 0.0:
            raise ValueError("conservative obstacle constraint needs gain > 0 and margin >= 0")
        self.gain = gain
        self.margin = margin

    def rows(self, context: StepContext) -> VelocityBounds:
        n = context.robot.dof
        limit = np.full(n, np.inf)
        radius = context.robot.base.body_radius + self.margin
        x, y = float(context.q[0]), float(context.q[1])
        for obstacle in context.obstacles:
            clearance = math.hypot(x - obstacle.x, y - obstacle.y) - obstacle.radius - radius
            limit[:2] = np.minimum(limit[:2], self.gain * max(clearance, 0.0))
        return VelocityBounds(self.name, -limit, limit)
