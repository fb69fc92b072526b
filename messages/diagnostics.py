"""What a controller did at one step, and why."""

from __future__ import annotations

from pydantic import Field

from messages.base import Finite, Message, NonNegative
from messages.header import Header
from messages.process import ParamValue


class ControllerDiagnostics(Message):
    """One control step.

    ``law`` names the control law (e.g. ``"lp"``, ``"pseudoinverse"``),
    ``status`` its outcome and ``reason`` a human explanation. ``objective`` is
    the optimal cost when there is one; ``nonzero`` counts the nonzero entries
    of ``u`` and ``practical_nonzero`` those above the practical threshold.
    ``active_constraints`` names the constraints at their bound,
    ``solve_time_us`` is the solve's wall time in microseconds, ``error_norm``
    the task error's norm, ``parameters`` every gain in force (a recording says what each step
    ran with).
    """

    header: Header
    law: str
    status: str
    reason: str = ""
    objective: Finite | None = None
    nonzero: int = Field(ge=0)
    practical_nonzero: int = Field(ge=0)
    active_constraints: tuple[str, ...] = ()
    solve_time_us: NonNegative
    error_norm: NonNegative | None = None
    parameters: dict[str, ParamValue] = Field(default_factory=dict)
