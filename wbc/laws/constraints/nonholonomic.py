"""The nonholonomic constraint of the differential-drive base (5.11, 5.12); none for an
omnidirectional base (holonomic) or a fixed one (its bounds on u_b are 0), whatever the gain."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc.laws.constraints.base import LinearRows
from wbc.laws.gains import gain
from wbc.laws.kept import zeros
from wbc.laws.step_context import StepContext


@dataclass(frozen=True)
class NonholonomicGains:
    nonholonomic: bool = gain(True, doc="False models a holonomic base (section 6.3, test 1)")


class Nonholonomic:
    """x' sin(phi) - y' cos(phi) = 0: W_nh u = 0, W_nh = [sin(phi), -cos(phi), 0, ..., 0]."""

    name = "nonholonomic"

    gains: ClassVar[tuple[type, ...]] = (NonholonomicGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> Nonholonomic | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        return cls() if params.nonholonomic else None

    def rows(self, context: StepContext) -> LinearRows:
        if context.robot.base.kind != "differential":
            empty = np.zeros(0)
            return LinearRows(self.name, np.zeros((0, context.robot.dof)), empty, empty, False)
        phi = float(context.q[2])
        row = np.zeros((1, context.robot.dof))
        row[0, 0], row[0, 1] = math.sin(phi), -math.cos(phi)
        zero = zeros(1)  # kept (wbc.laws.kept): the LP's buffers hold it from the last step
        return LinearRows(self.name, row, zero, zero)
