"""One declaration per gain: default, bounds, choices and doc, read by the law and the process.

A law's parameter dataclass declares each field with ``gain(...)``; a string field's choices
are its ``Literal`` annotation's. ``check_gains`` validates an instance against those
declarations, and a component's run-time parameters are those very declarations
(``components.params.Param`` is a ``GainSpec``), so a bound, a choice and the validator are
written once.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import typing
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

GAIN = "gain"


def shown(value: object, limit: int = 120) -> str:
    """``repr(value)``, cut to ``limit`` characters (an error never echoes a 50 MB value)."""
    text = repr(value)
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


@dataclass(frozen=True)
class GainSpec:
    """What may be set on one value: its ``type`` (bool, int, float, str; ``tuple``, a vector
    of ``length`` numbers; ``list``, any number of such vectors), its ``default``, inclusive
    bounds ``low`` and ``high`` for numbers, or the only values allowed (``choices``), and a
    one-line ``doc``. A vector is held as a tuple of floats, a list as a tuple of them."""

    name: str
    type: type
    default: Any
    low: float | None = None
    high: float | None = None
    choices: tuple[Any, ...] | None = None
    doc: str = ""
    length: int | None = None

    def __post_init__(self) -> None:
        self.check(self.default)

    def expected(self) -> str:
        """What a valid value is, in words: ``"a float in [0, 10]"``."""
        if self.type is tuple:
            return f"{self.length} finite numbers"
        if self.type is list:
            return f"a list of groups of {self.length} finite numbers"
        what = f"a {self.type.__name__}"
        if self.choices is not None:
            return f"{what} in {{{', '.join(map(repr, self.choices))}}}"
        if self.low is not None and self.high is not None:
            return f"{what} in [{self.low}, {self.high}]"
        if self.low is not None:
            return f"{what} >= {self.low}"
        if self.high is not None:
            return f"{what} <= {self.high}"
        return what

    def check(self, value: object) -> Any:
        """``value`` as this type (an int is taken for a float, a bool never for a number), or
        ``ValueError`` naming the value and saying what was expected."""
        if self.type in (tuple, list):
            return self._vectors(value)
        if self.type is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        number = isinstance(value, int | float) and not isinstance(value, bool)
        wrong = type(value) is not self.type or (number and not math.isfinite(value))
        outside = (
            number
            and not wrong
            and (
                (self.low is not None and value < self.low)
                or (self.high is not None and value > self.high)
            )
        )
        if wrong or outside or (self.choices is not None and value not in self.choices):
            raise ValueError(f"{self.name}: expected {self.expected()}, got {shown(value)}")
        return value

    def _vectors(self, value: object) -> tuple:
        """A vector (or list of vectors) as tuples of floats."""
        try:
            rows = [value] if self.type is tuple else list(value)
            held = tuple(self._vector(row) for row in rows)
        except (TypeError, ValueError):
            raise ValueError(
                f"{self.name}: expected {self.expected()}, got {shown(value)}"
            ) from None
        return held[0] if self.type is tuple else held

    def _vector(self, row: object) -> tuple[float, ...]:
        if isinstance(row, str | bytes) or len(row) != self.length:
            raise ValueError(row)
        if any(isinstance(v, bool) or not isinstance(v, int | float) for v in row):
            raise ValueError(row)
        numbers = tuple(float(v) for v in row)
        if not all(math.isfinite(v) for v in numbers):
            raise ValueError(row)
        return numbers


def gain(default: Any, *, doc: str, low: float | None = None, high: float | None = None) -> Any:
    """A dataclass field with its declaration (see ``GainSpec``; choices come from the
    field's ``Literal`` annotation)."""
    return dataclasses.field(default=default, metadata={GAIN: (low, high, doc)})


def composed(
    name: str,
    doc: str,
    parts: Sequence[type],
    module: str,
    defaults: Mapping[str, Any] | None = None,
) -> type:
    """A frozen dataclass ``name`` of every field of the gains dataclasses ``parts`` (each
    once, in order), validated on construction (``check_gains``, then each part's
    ``check_together``): a law's parameters, as each of its terms declares its own. A law that
    wants another default for a gain says it in ``defaults``."""
    defaults = dict(defaults or {})
    fields, seen = [], set()
    for part in dict.fromkeys(parts):
        hints = typing.get_type_hints(part)
        for field in dataclasses.fields(part):
            if field.name in seen:
                raise TypeError(f"{name}: two parts declare the gain {field.name!r}")
            seen.add(field.name)
            default = defaults.pop(field.name, field.default)
            fields.append(
                (
                    field.name,
                    hints[field.name],
                    dataclasses.field(default=default, metadata=field.metadata),
                )
            )
    if defaults:
        raise TypeError(f"{name}: no part declares {', '.join(defaults)}")
    checks = [part.check_together for part in parts if hasattr(part, "check_together")]

    def __post_init__(self) -> None:  # noqa: N807 - the dataclass hook
        check_gains(self)
        for check in checks:
            check(self)

    made = dataclasses.make_dataclass(
        name, fields, frozen=True, namespace={"__post_init__": __post_init__}
    )
    made.__doc__, made.__module__ = doc, module  # where pickle finds it
    return made


@functools.cache
def gain_specs(params_type: type) -> tuple[GainSpec, ...]:
    """The declarations of every field of a parameter dataclass."""
    hints = typing.get_type_hints(params_type)
    specs = []
    for field in dataclasses.fields(params_type):
        low, high, doc = field.metadata[GAIN]
        hint = hints[field.name]
        choices = typing.get_args(hint) if typing.get_origin(hint) is Literal else None
        specs.append(
            GainSpec(field.name, type(field.default), field.default, low, high, choices, doc)
        )
    return tuple(specs)


def check_gains(params: object) -> None:
    """ValueError naming ``Type.field`` for the first value its declaration refuses."""
    for spec in gain_specs(type(params)):
        try:
            spec.check(getattr(params, spec.name))
        except ValueError as error:
            raise ValueError(f"{type(params).__name__}.{error}") from None
