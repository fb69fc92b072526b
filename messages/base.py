"""The common base of every message and the field types they share.

Every float on the wire is finite: NaN and +-inf are rejected at validation, so
a controller never has to ask whether its input is a number. Fixed-size vectors
are tuples of that length, so a model is immutable all the way down (dicts
excepted). Units are SI, angles are radians. The arm's joints are as many as its
robot description names: no joint count is fixed here.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import AfterValidator, AllowInfNan, BaseModel, ConfigDict, Field

UINT64_MAX = 2**64 - 1
"""Largest integer msgpack carries; counters and stamps stay below it."""

UNIT_TOLERANCE = 1e-6
"""How far a unit dual quaternion may stray from ``x * conj(x) == 1``."""

Finite = Annotated[float, AllowInfNan(False)]
"""Any finite float."""

NonNegative = Annotated[float, AllowInfNan(False), Field(ge=0.0)]
"""A finite float >= 0."""

Positive = Annotated[float, AllowInfNan(False), Field(gt=0.0)]
"""A finite float > 0."""

Count = Annotated[int, Field(ge=0, le=UINT64_MAX)]
"""A non-negative integer that fits in an unsigned 64-bit word."""

Vector3 = tuple[Finite, Finite, Finite]
"""A point or vector in R^3, metres unless a field says otherwise."""

ArmVector = Annotated[tuple[Finite, ...], Field(min_length=1)]
"""One value per arm joint, as many as the robot has (rad or m, rad/s or m/s)."""


def default_joint_names(count: int) -> tuple[str, ...]:
    """``q1 .. q<count>``: the names of a DH table's joints when it names none, and of a
    message's joints when its sender named none (recordings made before messages named them)."""
    return tuple(f"q{i}" for i in range(1, count + 1))


def check_joint_names(names: tuple[str, ...], values: tuple[float, ...], field: str) -> None:
    """Refuse ``names`` unless they are unique and as many as ``values`` (``field``'s)."""
    if len(names) != len(values):
        raise ValueError(f"joint_names has {len(names)} names, {field} {len(values)} values")
    if len(set(names)) != len(names):
        raise ValueError(f"joint_names {names} are not unique")


def with_default_joint_names(data: Any, field: str) -> Any:
    """``data`` (a model's input) with ``joint_names`` filled in as ``default_joint_names``
    of ``field``'s length when it has none."""
    if isinstance(data, dict) and "joint_names" not in data:
        values = data.get(field)
        if isinstance(values, (tuple, list)):
            return {**data, "joint_names": default_joint_names(len(values))}
    return data


def _check_unit(dq: tuple[float, ...]) -> tuple[float, ...]:
    """Accept ``x = P + eps D`` only if ``x * conj(x) = 1``.

    The primary part of ``x * conj(x)`` is ``|P|^2`` and its dual part is
    ``2 P.D`` (4-vector dot product), so we need ``|P| = 1`` and ``P.D = 0``.
    """
    primary, dual = dq[:4], dq[4:]
    norm = math.sqrt(math.fsum(p * p for p in primary))
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise ValueError(f"primary part has norm {norm:.9g}, expected 1 (tolerance 1e-6)")
    dual_part = 2.0 * math.fsum(p * d for p, d in zip(primary, dual, strict=True))
    if abs(dual_part) > UNIT_TOLERANCE:
        raise ValueError(f"dual part of x*conj(x) is {dual_part:.9g}, expected 0 (tolerance 1e-6)")
    return dq


UnitDualQuaternion = Annotated[
    tuple[Finite, Finite, Finite, Finite, Finite, Finite, Finite, Finite],
    AfterValidator(_check_unit),
]
"""A pose as a unit dual quaternion ``[1, i, j, k, e, ei, ej, ek]`` (DQ Robotics order)."""

IDENTITY_POSE: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
"""The unit dual quaternion of no rotation and no translation."""


class Message(BaseModel):
    """Base of every model: immutable, and unknown fields are an error."""

    model_config = ConfigDict(frozen=True, extra="forbid")
