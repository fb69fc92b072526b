"""The least-velocity cost (wbc/laws/objectives/velocity_cost.py)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.wbc.laws.objectives.objective_steps import MODEL, context
from wbc.geometry.scenarios import HOME
from wbc.laws.objectives.velocity_cost import LeastVelocity


def test_least_velocity_weighs_every_entry_of_u():
    cost = LeastVelocity(1e-3).cost(context(HOME, None, np.ones(8)))
    np.testing.assert_array_equal(cost.weights, np.full(MODEL.dof, 1e-3))


@pytest.mark.parametrize(
    "make",
    [
        lambda: LeastVelocity(float("nan")),
    ],
)
def test_an_invalid_least_velocity_weight_is_refused(make):
    with pytest.raises(ValueError):
        make()
