"""One declaration per gain: default, bounds, choices and doc, read by the law and the process.

A law's parameter dataclass declares each field with ``gain(...)``; ``check_gains`` validates
an instance against those declarations, and a component derives its run-time parameters from
``gain_specs`` (``components.controller.law_params``), so a bound is written once.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

GAIN = "gain"


@dataclass(frozen=True)
class GainSpec:
    """What may be set on one field: its ``type`` (that of its default), inclusive bounds
    ``low`` and ``high`` for numbers, or the ``choices`` of a string, and a one-line ``doc``."""

    name: str
    type: type
    default: Any
    low: float | None
    high: float | None
    choices: tuple[str, ...] | None
    doc: str

    def problem(self, value: object) -> str | None:
        """Why ``value`` cannot be this gain, or None."""
        if self.type is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if type(value) is not self.type:
            return f"must be a {self.type.__name__}, got {value!r}"
        if isinstance(value, float) and not math.isfinite(value):
            return f"must be finite, got {value}"
        low = -math.inf if self.low is None else self.low
        high = math.inf if self.high is None else self.high
        if isinstance(value, float) and not low <= value <= high:
            return f"must be in [{self.low}, {self.high}], got {value}"
        if self.choices is not None and value not in self.choices:
            return f"must be one of {', '.join(map(repr, self.choices))}, got {value!r}"
        return None


def gain(
    default: Any,
    *,
    doc: str,
    low: float | None = None,
    high: float | None = None,
    choices: tuple[str, ...] | None = None,
) -> Any:
    """A dataclass field with its declaration (see ``GainSpec``)."""
    return dataclasses.field(default=default, metadata={GAIN: (low, high, choices, doc)})


def gain_specs(params_type: type) -> tuple[GainSpec, ...]:
    """The declarations of every field of a parameter dataclass."""
    specs = []
    for field in dataclasses.fields(params_type):
        low, high, choices, doc = field.metadata[GAIN]
        specs.append(GainSpec(field.name, type(field.default), field.default, low, high,
                              choices, doc))  # fmt: skip
    return tuple(specs)


def check_gains(params: object) -> None:
    """ValueError naming ``Type.field`` for the first value its declaration refuses."""
    for spec in gain_specs(type(params)):
        problem = spec.problem(getattr(params, spec.name))
        if problem is not None:
            raise ValueError(f"{type(params).__name__}.{spec.name} {problem}")
