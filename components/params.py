"""Declared parameters of a component, set by the profile and changed at run time.

A component declares each parameter with its type, default and optional
bounds; the profile's ``params`` override the defaults at start, and
``parsimony param set`` changes them while the component runs. On the wire
(the param queryable), a get has no payload, a set carries the new value as
text (``"0.5"``, ``"true"``), and the reply is the value as JSON; errors are
replied as plain text.
"""

from __future__ import annotations

import dataclasses
import json
import logging
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from messages.process import ParamValue
from wbc.laws.gains import GainSpec, shown
from wbc.robot import MobileManipulator

log = logging.getLogger("components")

_TRUE = ("true", "yes", "on", "1")
_FALSE = ("false", "no", "off", "0")


class ParamError(ValueError):
    """An unknown parameter name, or a value of the wrong type or out of bounds."""


@dataclass(frozen=True)
class Param(GainSpec):
    """A declared parameter: a ``GainSpec`` (name, type, default, bounds, choices, doc; its
    validator), with an optional ``can_take`` check. A vector (``tuple``) may hold
    ``integers`` (servo ids) rather than floats, and may be ``optional``: empty for none."""

    can_take: Callable[[ParamValue], None] | None = field(default=None, compare=False)
    """Raises ``ParamError`` when a value of the right type could not take effect (a robot
    file that does not load): such a value is refused when set, not failed on later."""
    integers: bool = False
    """A vector of integers, held as ints (a float, even 1.0, is refused)."""
    optional: bool = False
    """A vector that may be empty, ``[]``: none given."""

    def expected(self) -> str:
        if self.type is not tuple or not (self.integers or self.optional):
            return super().expected()
        what = f"{self.length} {'integers' if self.integers else 'finite numbers'}"
        return f"{what} in a list, or [] for none" if self.optional else f"{what} in a list"

    def _vector(self, row: object) -> tuple:
        if self.optional and isinstance(row, tuple | list) and not row:
            return ()
        numbers = super()._vector(row)
        if not self.integers:
            return numbers
        if not all(isinstance(v, int) for v in row):  # super() refused bools and non-numbers
            raise ValueError(row)
        return tuple(row)

    @classmethod
    def of(cls, spec: GainSpec) -> Param:
        """The run-time parameter of a law's gain, as declared."""
        return cls(**{f.name: getattr(spec, f.name) for f in dataclasses.fields(GainSpec)})

    def check(self, value: object) -> ParamValue:
        """``value`` as this parameter's type, or ``ParamError`` saying what was expected."""
        try:
            value = super().check(value)
        except ParamError:
            raise
        except ValueError as error:
            raise ParamError(str(error)) from None
        if self.can_take is not None:
            self.can_take(value)
        return value

    def parse(self, text: str) -> ParamValue:
        """The value written as ``text`` (as typed on a command line), checked."""
        text = text.strip() if self.type is not str else text
        try:
            if self.type in (tuple, list):  # JSON: [0.6, 0, 0], or [[1, 0, 0.1], [2, 0, 0.1]]
                value = json.loads(text)
            elif self.type is bool:
                if text.lower() not in _TRUE + _FALSE:
                    raise ValueError(text)
                value: ParamValue = text.lower() in _TRUE
            else:
                value = self.type(text)
        except ValueError:
            expected = self.expected()
            raise ParamError(f"{self.name}: expected {expected}, got {shown(text)}") from None
        return self.check(value)


class Parameters(Mapping[str, ParamValue]):
    """The current values of a component's declared parameters, read like a dict.

    ``version`` counts the changes since start, so a component can tell cheaply whether
    anything derived from the values must be computed again.
    """

    def __init__(self, declared: Iterable[Param], overrides: Mapping[str, object]) -> None:
        self.declared = {param.name: param for param in declared}
        unknown = sorted(set(overrides) - set(self.declared))
        if unknown:
            raise ParamError(
                f"{', '.join(unknown)}: unknown parameter; "
                f"declared: {', '.join(self.declared) or 'none'}"
            )
        self._values = {name: param.check(param.default) for name, param in self.declared.items()}
        self.version = 0
        self.changed: dict[str, ParamValue] = {}
        """The values set while the component runs (what a restart must keep)."""
        for name, value in overrides.items():
            self._values[name] = self.declared[name].check(value)

    def __getitem__(self, name: str) -> ParamValue:
        return self._values[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def param(self, name: str) -> Param:
        """The declaration of ``name``, or ``ParamError`` listing the declared names."""
        if name not in self.declared:
            raise ParamError(
                f"unknown parameter {name!r}; declared: {', '.join(self.declared) or 'none'}"
            )
        return self.declared[name]

    def set_text(self, name: str, text: str) -> ParamValue:
        """Set ``name`` from its text form and return the new value."""
        return self.set(name, self.param(name).parse(text))

    def set(self, name: str, value: object) -> ParamValue:
        """Set ``name`` to ``value`` (checked) and return it."""
        value = self.param(name).check(value)
        self._values[name] = self.changed[name] = value
        self.version += 1
        return value


def restore_params(params: Parameters, path: Path) -> None:
    """Set again the parameters an earlier run kept in ``path``; skip (and log) any refused now."""
    if not path.is_file():
        return
    try:
        kept = json.loads(path.read_text())
    except (OSError, ValueError) as error:
        log.warning("%s: cannot read kept parameters: %s", path, error)
        return
    for name, value in kept.items():
        try:
            params.set(name, value)
        except ParamError as error:
            log.warning("kept parameter not restored: %s", error)
    if params.changed:
        log.info("parameters restored from the last run: %s", params.changed)


def keep_params(params: Parameters, path: Path) -> None:
    """Write the parameters set at run time to ``path``, where the next run finds them."""
    partial_file = path.with_suffix(".tmp")
    partial_file.write_text(json.dumps(params.changed))
    partial_file.replace(path)


def load_robot(path: Path) -> MobileManipulator:
    """The robot described at ``path``, or ``ParamError`` saying why it cannot be loaded."""
    try:
        return MobileManipulator.from_yaml(path)
    except (OSError, ValueError, yaml.YAMLError) as error:
        raise ParamError(f"robot: cannot load {path}: {error}") from error
