"""Go round an obstacle when the base stalls on its border: w |t . p' - v|.

The border constraint (5.28, wbc.laws.constraints.obstacle_border) fixes the radial velocity of the
base's point p on the border and leaves its tangential velocity free. When the start, the
obstacle and the goal lie near one line, the task gains nothing to first order from either
tangent, so the LP's best step is to stand still on the border: a saddle (seed 1 of the
obstacle experiment stalled there at error 0.65). Once p has stood still by an obstacle (moving
slower than ``stall_speed``) for ``stall_time``, within ``near`` of the circle of the border
(5.28's, or the vector-field inequality's, which stops p just short of it), with the obstacle
between p and the goal, this term asks p to move along the border at
``speed``, t the unit tangent on the side the base heads to (counter-clockwise when it faces
the centre exactly), until the obstacle no longer stands between p and the goal (5.25's h < 0)
or p is ``release`` beyond the border. Away from a stall the task already picks its
side, and the term stays off: acting on every engaged border, it bent 9 of 40 seeds' ways round
the wrong side. It is a cost, not a row: u = 0 stays feasible.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc.laws.constraints.obstacle_border import border, point_velocity_row
from wbc.laws.constraints.obstacle_gains import ObstacleGains
from wbc.laws.gains import gain
from wbc.laws.objectives.base import ResidualCost, no_cost
from wbc.laws.step_context import StepContext


@dataclass(frozen=True)
class CirculationGains:
    obstacle_circulation: float = gain(
        0.2,
        low=0.0,
        high=1.0,
        doc="weight of going round an obstacle on the goal's "
        "side while its border is engaged "
        "(wbc.laws.objectives.obstacle_circulation)",
    )
    circulation_speed: float = gain(
        0.1, low=0.0, high=1.0, doc="the speed along the border that term asks for, m/s"
    )


class ObstacleCirculation:
    """weight * |t . p' - speed| for the obstacle whose engaged border p stalled on."""

    name = "obstacle_circulation"

    gains: ClassVar[tuple[type, ...]] = (ObstacleGains, CirculationGains)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> ObstacleCirculation | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        on = params.obstacle_mode in ("border", "vector_field") and params.obstacle_circulation > 0
        return (
            cls(
                params.obstacle_circulation,
                params.circulation_speed,
                params.obstacle_margin,
                params.obstacle_lookahead,
            )
            if on
            else None
        )

    def __init__(
        self,
        weight: float,
        speed: float,
        margin: float,
        lookahead: float,
        stall_speed: float = 0.01,
        stall_time: float = 0.5,
        release: float = 0.3,
        near: float = 0.05,
    ) -> None:
        if not (
            weight >= 0.0
            and speed >= 0.0
            and margin >= 0.0
            and lookahead >= 0.0
            and stall_speed >= 0.0
            and stall_time >= 0.0
            and release >= near >= 0.0
        ):
            raise ValueError(
                "obstacle circulation needs weight, speed, margin, lookahead, "
                "stall_speed, stall_time >= 0 and release >= near >= 0"
            )
        self.weight, self.speed = weight, speed
        self.margin, self.lookahead = margin, lookahead
        self.stall_speed, self.stall_time = stall_speed, stall_time
        self.release, self.near = release, near
        self.reset()

    def reset(self) -> None:
        self._point: tuple[float, float] | None = None
        self._stalled_s = 0.0
        self._side = 0.0
        """+1 counter-clockwise, -1 clockwise once circulating; 0 before."""

    def cost(self, context: StepContext) -> ResidualCost:
        dof = context.robot.dof
        phi = float(context.q[2])
        point = (
            float(context.q[0]) + self.lookahead * math.cos(phi),
            float(context.q[1]) + self.lookahead * math.sin(phi),
        )
        moved = math.inf if self._point is None else math.dist(point, self._point)
        self._point = point
        for obstacle in context.obstacles:
            at = border(context, obstacle, self.margin, self.lookahead)
            norm = math.hypot(at.dx, at.dy) or 1.0
            radius = math.sqrt(max(at.f + norm * norm, 0.0))
            if self._side != 0.0 and at.h > 0.0 and norm < radius + self.release:
                tangent = (-self._side * at.dy / norm, self._side * at.dx / norm)
                row = point_velocity_row(*tangent, phi, self.lookahead, dof)
                return ResidualCost(
                    self.name, row[np.newaxis], np.array([-self.speed]), self.weight
                )
            if not (at.h > 0.0 and norm < radius + self.near):
                continue
            slow = context.dt > 0.0 and moved < self.stall_speed * context.dt
            self._stalled_s = self._stalled_s + context.dt if slow else 0.0
            if self._stalled_s >= self.stall_time:
                ahead = -at.dy * math.cos(phi) + at.dx * math.sin(phi)  # ccw tangent . heading
                self._side = 1.0 if ahead >= 0.0 else -1.0
            break
        else:
            self._stalled_s, self._side = 0.0, 0.0
        return no_cost(self.name, dof)
