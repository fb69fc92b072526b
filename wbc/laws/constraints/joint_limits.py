"""Joint position and velocity limits as bounds on u (5.13-5.18), the base included."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc.laws.constraints.base import VelocityBounds
from wbc.laws.gains import gain
from wbc.laws.step_context import StepContext
from wbc.robot import MobileManipulator

Array = np.ndarray


@dataclass(frozen=True)
class JointLimitGains:
    joint_gain: float = gain(1.0, low=1e-3, high=1e4, doc="k of 5.14, 1/s")
    safety_factor: float = gain(0.9, low=0.01, high=1.0, doc="beta_l of 5.14")


class JointLimits:
    """max(q'-, k (b_l q- - q)) <= u <= min(q'+, k (b_l q+ - q)) (5.15).

    k > 0 (``gain``, 1/s) scales how fast a joint may approach its limit; 0 << b_l <= 1
    (``safety_factor``) shrinks the range [q-, q+] (``MobileManipulator.joint_box``). Entries
    with infinite position limits (the base's x, y, phi) keep their velocity bounds only.
    Where a joint already lies outside b_l [q-, q+], the bounds leave it only the way back, at
    most at its speed limit.
    """

    name = "joint_limits"

    gains: ClassVar[tuple[type, ...]] = (JointLimitGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> JointLimits | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        return cls(params.joint_gain, params.safety_factor)

    def __init__(self, gain: float = 1.0, safety_factor: float = 0.9) -> None:
        if gain <= 0.0 or not 0.0 < safety_factor <= 1.0:
            raise ValueError("joint limits need gain > 0 and 0 < safety_factor <= 1")
        self.gain = gain
        self.safety_factor = safety_factor
        self._robot: MobileManipulator | None = None
        self._limits: tuple[Array, Array, Array] = (np.zeros(0),) * 3

    def _scaled(self, robot: MobileManipulator) -> tuple[Array, Array, Array]:
        """k b_l q-, k b_l q+ and -q'+ of ``robot``, kept for the robot last seen."""
        if robot is not self._robot:
            low, high = robot.joint_box(self.safety_factor)
            self._limits = (self.gain * low, self.gain * high, -robot.velocity_max)
            self._robot = robot
        return self._limits

    def rows(self, context: StepContext) -> VelocityBounds:
        speed = context.robot.velocity_max
        low, high, slowest = self._scaled(context.robot)
        scaled_q = self.gain * context.q
        # k (b_l q-+ - q), infinite for the base's x, y, phi; then held inside [-q'+, q'+].
        lower = np.maximum(low - scaled_q, slowest)
        upper = np.minimum(high - scaled_q, speed)
        np.minimum(lower, speed, out=lower)
        np.maximum(upper, slowest, out=upper)
        return VelocityBounds(
            self.name, np.minimum(lower, upper), np.maximum(lower, upper), ordered=True
        )
