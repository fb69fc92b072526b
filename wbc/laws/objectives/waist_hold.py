"""Yaw by the base, the waist held: an extra w |q1'| on top of the tie-break.

On this robot the base-yaw column of the whole-body Jacobian equals the waist's (q1), so the
task's yaw can go to either, and any split of it between the two is an extra nonzero entry of
u (a vertex has one of them 0). 5.29 leaves the choice to the simplex, which then turns the
waist far from the base's heading. This term makes the waist dearer than the base: the base
takes the task's yaw and faces where the arm works, and the waist moves only when the base
cannot, or for the waist centring term (wbc.laws.objectives.waist_centring). It is a velocity cost,
so the solution stays a vertex: it costs no entry.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc.laws.gains import gain
from wbc.laws.objectives.base import VelocityCost
from wbc.laws.step_context import StepContext
from wbc.robot import BASE_DOF


@dataclass(frozen=True)
class WaistHoldGains:
    waist_hold: float = gain(
        0.02,
        low=0.0,
        high=1.0,
        doc="extra weight of |q1'|: the task's yaw goes to the base, the "
        "waist holds (wbc.laws.objectives.waist_hold)",
    )


class WaistHold:
    """weight * |q1'|."""

    name = "waist_hold"

    gains: ClassVar[tuple[type, ...]] = (WaistHoldGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> WaistHold | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        return cls(params.waist_hold) if params.waist_hold > 0.0 else None

    def __init__(self, weight: float) -> None:
        if not weight >= 0.0:
            raise ValueError(f"waist hold weight must be >= 0, got {weight}")
        self.weight = weight
        self._cost: VelocityCost | None = None

    def cost(self, context: StepContext) -> VelocityCost:
        if self._cost is None or self._cost.weights.size != context.robot.dof:
            weights = np.zeros(context.robot.dof)
            weights[BASE_DOF] = self.weight
            weights.flags.writeable = False
            self._cost = VelocityCost(self.name, weights)
        return self._cost

    def reset(self) -> None:
        """Stateless."""
