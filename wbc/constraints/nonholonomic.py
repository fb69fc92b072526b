"""The nonholonomic constraint of the differential-drive base (5.11, 5.12)."""

from __future__ import annotations

import math

import numpy as np

from wbc.constraints.base import LinearRows
from wbc.step_context import StepContext


class Nonholonomic:
    """x' sin(phi) - y' cos(phi) = 0: W_nh u = 0, W_nh = [sin(phi), -cos(phi), 0, ..., 0]."""

    name = "nonholonomic"

    def rows(self, context: StepContext) -> LinearRows:
        phi = float(context.q[2])
        row = np.zeros((1, context.robot.dof))
        row[0, 0], row[0, 1] = math.sin(phi), -math.cos(phi)
        zero = np.zeros(1)
        return LinearRows(self.name, row, zero, zero)
