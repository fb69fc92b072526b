"""Plücker lines as dual quaternions (wbc/geometry/plucker.py): the closest points of two lines."""

from __future__ import annotations

import numpy as np
import pytest

from wbc.geometry.plucker import closest_parameters, line


def test_closest_parameters_give_the_common_perpendicular() -> None:
    first, second = line([1, 0, 0], [0, 0, 1]), line([0, 1, 0], [2, 0, -1])
    s, t, skew = closest_parameters(first, second)
    np.testing.assert_allclose([s.item(), t.item(), skew.item()], [2.0, 0.0, 1.0], atol=1e-12)
    _, _, parallel = closest_parameters(first, line([-1, 0, 0], [0, 1, 0]))
    assert parallel.item() == pytest.approx(0.0)
    many, _, _ = closest_parameters(np.array([first, second]), np.array([second, first]))
    np.testing.assert_allclose(many, [[2.0, np.nan], [np.nan, 0.0]], atol=1e-12)  # parallel: nan
