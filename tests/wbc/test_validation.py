"""Input checks (wbc/validation.py): nothing non-finite reaches a solver or a motor."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wbc.validation import NonFiniteInputError, require_finite


def test_finite_input_comes_back_as_a_float_array() -> None:
    array = require_finite("q", [1, 2, 3])
    assert array.dtype == np.float64
    np.testing.assert_array_equal(array, [1.0, 2.0, 3.0])
    assert require_finite("dt", 0.01).shape == ()


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_entries_are_named(bad: float) -> None:
    with pytest.raises(NonFiniteInputError) as raised:
        require_finite("configuration q", [0.0, bad, 1.0, bad])
    message = str(raised.value)
    assert "configuration q" in message
    assert "[1, 3]" in message


def test_non_finite_input_error_is_a_value_error() -> None:
    with pytest.raises(ValueError):
        require_finite("error", np.array([[0.0, math.nan]]))
