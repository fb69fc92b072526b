"""A parameter vector whose length the robot decides (an entry per joint): any length from
``least`` up, checked against the robot where the component loads it (``of_robot``)."""

from __future__ import annotations

from dataclasses import dataclass

from components.params import Param, ParamError


@dataclass(frozen=True)
class RobotVector(Param):
    """A ``tuple`` parameter of any number of values, at least ``least`` (``integers`` or
    finite numbers, as ``Param``'s); ``length`` is left unset."""

    least: int = 1

    def expected(self) -> str:
        what = "integers" if self.integers else "finite numbers"
        more = f"{self.least} or more {what} in a list"
        return f"{more}, or [] for none" if self.optional else more

    def _vector(self, row: object) -> tuple:
        if isinstance(row, str | bytes) or not isinstance(row, tuple | list):
            raise ValueError(row)
        if self.optional and not row:
            return ()
        if len(row) < self.least:
            raise ValueError(row)
        exact = Param(self.name, tuple, tuple(row), length=len(row), integers=self.integers)
        return exact.check(row)


def of_robot(name: str, values: tuple, count: int, what: str) -> tuple:
    """``values`` of parameter ``name`` if they are ``count``, else ``ParamError`` saying they
    are ``what`` (the robot's joints they stand for)."""
    if len(values) != count:
        raise ParamError(f"{name}: expected {count} values ({what}), got {len(values)}: {values}")
    return values
