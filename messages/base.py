"""The common base of every message and the field types they share.

Every float on the wire is finite: NaN and +-inf are rejected at validation, so
a controller never has to ask whether its input is a number. Fixed-size vectors
are tuples of that length, so a model is immutable all the way down (dicts
excepted). Units are SI, angles are radians.
"""

from __future__ import annotations

import math
from typing import Annotated

from pydantic import AfterValidator, AllowInfNan, BaseModel, ConfigDict, Field

UINT64_MAX = 2**64 - 1
"""Largest integer msgpack carries; counters and stamps stay below it."""

UNIT_TOLERANCE = 1e-6
"""How far a unit dual quaternion may stray from ``x * conj(x) == 1``."""

ARM_JOINTS = 5
"""Number of joints of the arm; joint vectors have exactly this length."""

JOINT_NAMES = tuple(f"q{i}" for i in range(1, ARM_JOINTS + 1))
"""The arm's joint names in joint-state messages, q1 at the waist."""

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

ArmVector = tuple[Finite, Finite, Finite, Finite, Finite]
"""One value per arm joint, ``ARM_JOINTS`` long (rad or rad/s)."""


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
