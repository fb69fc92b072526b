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
