"""What an objective term returns (wbc/laws/objectives/base.py): a latch that acts in bursts."""

from __future__ import annotations

import pytest

from wbc.laws.objectives.base import Latch, VelocityCost


def test_a_latch_is_on_above_on_and_off_again_only_below_off() -> None:
    latch = Latch(on=0.3, off=0.05)
    assert [latch.update(x) for x in (0.2, -0.4, 0.2, 0.06, 0.01, 0.2)] == [
        False,
        True,
        True,
        True,
        False,
        False,
    ]


@pytest.mark.parametrize(("on", "off"), [(0.3, 0.3), (0.3, -0.1)])
def test_a_latch_needs_off_below_on(on: float, off: float) -> None:
    with pytest.raises(ValueError, match="0 <= off < on"):
        Latch(on=on, off=off)


def test_a_velocity_cost_weighs_both_directions_alike_unless_told() -> None:
    assert VelocityCost("c", weights=(1.0, 2.0)).negative_weights == (1.0, 2.0)
    assert VelocityCost("c", (1.0, 2.0), negative=(0.0, 0.0)).negative_weights == (0.0, 0.0)
