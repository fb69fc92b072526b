"""Spend the waist/base-yaw self-motion on keeping the waist centred: w |q1' + k q1|.

On this robot the base-yaw column of the whole-body Jacobian equals the waist (q1) column, so
phi' = -q1' moves no part of the end effector: under the nonholonomic equality it is the only
instantaneous redundancy. 5.29 leaves it to chance; this term asks for q1' = -k q1, which the
base's turn can absorb at no cost to the task. The base then turns to face where the arm
reaches, and the waist keeps its range for the task instead of stalling at its limit.

It is off by default (weight 0): whenever it acts, phi' and q1' are both nonzero, an eighth
entry of u, and with the waist hold term (wbc.laws.objectives.waist_hold), which keeps the waist
where it is at no cost in entries, it lowered the share of `parsimony bench`'s 'ahead' goals
reached (weight 0.05: 0.93 and 0.88 on two sets of 100, against 0.94 and 0.90 without it).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc.laws.gains import gain
from wbc.laws.objectives.base import ResidualCost, unit_row
from wbc.laws.step_context import StepContext
from wbc.robot import BASE_DOF


@dataclass(frozen=True)
class WaistCentringGains:
    waist_centring: float = gain(
        0.0,
        low=0.0,
        high=1.0,
        doc="weight of |q1' + k q1|: the waist/base-yaw self-motion "
        "spent on a centred waist (wbc.laws.objectives.waist_centring)",
    )
    waist_gain: float = gain(1.0, low=1e-3, high=100.0, doc="k of the waist centring, 1/s")
    waist_fade: float = gain(
        0.05, low=0.0, high=10.0, doc="||e||_1 below which the waist centring fades out (0: never)"
    )


class WaistCentring:
    """weight * f * |q1' + gain q1|, faded by f = min(1, ||e||_1 / fade_error).

    The term competes with the task for the budget of 5.10, which shrinks with e'; near the
    goal, where the task needs all of it, the fade hands it back (fade_error 0: no fade).
    """

    name = "waist_centring"

    gains: ClassVar[tuple[type, ...]] = (WaistCentringGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> WaistCentring | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        on = params.waist_centring > 0.0
        return cls(params.waist_centring, params.waist_gain, params.waist_fade) if on else None

    def __init__(self, weight: float, gain: float, fade_error: float = 0.0) -> None:
        if not (weight >= 0.0 and gain > 0.0 and fade_error >= 0.0):
            raise ValueError("waist centring needs weight >= 0, gain > 0 and fade_error >= 0")
        self.weight, self.gain, self.fade_error = weight, gain, fade_error

    def cost(self, context: StepContext) -> ResidualCost:
        row = unit_row(context.robot.dof, BASE_DOF)
        fade = 1.0
        if self.fade_error > 0.0:
            fade = min(1.0, float(np.abs(context.error).sum()) / self.fade_error)
        offset = np.array([self.gain * context.q[BASE_DOF]])
        return ResidualCost(self.name, row, offset, self.weight * fade)

    def reset(self) -> None:
        """Stateless."""
