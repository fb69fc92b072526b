"""The bound on ||u||_1 that makes u vanish when the task stops: 5.10, or the original 5.7."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Literal, get_args

import numpy as np

from wbc.laws.constraints.base import OneNormBound
from wbc.laws.gains import gain
from wbc.laws.step_context import StepContext

ErrorBoundMode = Literal["derivative", "error"]
"""What the bound measures: e' (5.10) or e (5.7)."""


@dataclass(frozen=True)
class ErrorBoundGains:
    beta: float = gain(15.0, low=1e-3, high=1e3, doc="bound gain of 5.10 / 5.7")
    error_bound: ErrorBoundMode = gain(
        "derivative", doc="5.10 (bound on ||e'||_1) or the original 5.7 (bound on ||e||_1)"
    )


class ErrorBound:
    """||u||_1 <= beta ||vec e'||_1 (5.10), or ||u||_1 <= beta ||vec e||_1 (5.7).

    With the error-derivative form the joints stop when the end effector stalls short of the
    goal (e' = 0); with the error form they may keep moving as long as e != 0.
    """

    gains: ClassVar[tuple[type, ...]] = (ErrorBoundGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> ErrorBound | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        return cls(params.beta, params.error_bound)

    def __init__(self, beta: float, mode: ErrorBoundMode = "derivative") -> None:
        if beta <= 0.0 or mode not in get_args(ErrorBoundMode):
            raise ValueError(f"error bound needs beta > 0 and a mode in {get_args(ErrorBoundMode)}")
        self.beta = beta
        self.mode = mode
        self.name = "error_derivative_bound" if mode == "derivative" else "error_bound"

    def rows(self, context: StepContext) -> OneNormBound:
        measure = context.error_rate if self.mode == "derivative" else context.error
        return OneNormBound(self.name, self.beta * float(np.add.reduce(np.abs(measure))))
