"""Input checks shared by the control laws: nothing non-finite reaches a solver or a motor."""

from __future__ import annotations

import numpy as np


class NonFiniteInputError(ValueError):
    """An input to a control law holds NaN or infinity."""


def require_finite(name: str, value: object) -> np.ndarray:
    """``value`` as a float array, or NonFiniteInputError naming ``name`` and the bad entries."""
    array = np.asarray(value, dtype=float)
    if not np.isfinite(array).all():
        bad = np.flatnonzero(~np.isfinite(array.ravel())).tolist()
        raise NonFiniteInputError(f"{name} must be finite; entries {bad} are {array.ravel()[bad]}")
    return array


def require_positive(params: object, *names: str) -> None:
    """ValueError naming ``Type.field`` for the first of ``names`` that is not finite and > 0."""
    for name in names:
        value = getattr(params, name)
        if not np.isfinite(value) or value <= 0.0:
            raise ValueError(f"{type(params).__name__}.{name} must be finite and > 0, got {value}")
