"""The error bound (wbc/laws/constraints/error_bound.py; 5.7, 5.10)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.wbc.laws.constraints.constraint_steps import (
    NO_DEADLINE,
    context,
    finite,
)
from wbc.laws.constraints.base import OneNormBound
from wbc.laws.constraints.error_bound import ErrorBound


@NO_DEADLINE
@given(
    st.floats(0.01, 100.0),
    st.lists(finite, min_size=8, max_size=8),
    st.lists(finite, min_size=8, max_size=8),
)
def test_error_bound_limit(beta: float, error: list[float], error_rate: list[float]) -> None:
    step = context(error=np.array(error), error_rate=np.array(error_rate))
    derivative = ErrorBound(beta).rows(step)
    assert isinstance(derivative, OneNormBound)
    assert derivative.limit == pytest.approx(beta * sum(abs(v) for v in error_rate))
    assert derivative.name == "error_derivative_bound"
    original = ErrorBound(beta, mode="error").rows(step)
    assert original.limit == pytest.approx(beta * sum(abs(v) for v in error))
    assert original.name == "error_bound"


def test_error_bound_vanishes_when_the_end_effector_stalls() -> None:
    """e != 0 but e' = 0: the derivative form (5.10) stops the joints, the original (5.7) not."""
    step = context(error=np.full(8, 0.1), error_rate=np.zeros(8))
    assert ErrorBound(2.0).rows(step).limit == 0.0
    assert ErrorBound(2.0, mode="error").rows(step).limit == pytest.approx(1.6)


@pytest.mark.parametrize(("beta", "mode"), [(0.0, "derivative"), (-1.0, "error"), (1.0, "both")])
def test_error_bound_rejects_bad_parameters(beta: float, mode: str) -> None:
    with pytest.raises(ValueError):
        ErrorBound(beta, mode)  # type: ignore[arg-type]
