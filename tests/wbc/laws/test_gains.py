"""One declaration per gain (wbc/laws/gains.py): a law's parameters composed of its terms' gains,
each value checked against its declaration on construction."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import pytest

from wbc.laws.constraints.obstacle_gains import ObstacleGains
from wbc.laws.gains import composed, gain, gain_specs


@dataclass(frozen=True)
class SpeedGains:
    speed: float = gain(1.0, low=0.0, high=2.0, doc="how fast, m/s")
    mode: Literal["slow", "fast"] = gain("slow", doc="which way")


def made(**defaults):
    return composed("Made", "test", [SpeedGains, ObstacleGains], __name__, defaults)


def test_a_composed_type_holds_every_part_gain_with_its_declaration() -> None:
    params = made(speed=1.5)()
    assert params.speed == 1.5 and params.obstacle_mode == "vector_field"
    specs = {spec.name: spec for spec in gain_specs(type(params))}
    assert (specs["speed"].low, specs["speed"].high) == (0.0, 2.0)
    assert specs["mode"].choices == ("slow", "fast")


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"speed": 3.0}, r"Made\.speed: expected a float in \[0.0, 2.0\], got 3.0"),
        ({"speed": True}, "Made.speed: expected a float"),
        ({"mode": "fastest"}, r"Made\.mode: expected a str in \{'slow', 'fast'\}"),
        ({"obstacle_margin": float("nan")}, "Made.obstacle_margin"),
    ],
)
def test_a_value_its_declaration_refuses_is_named_with_what_was_expected(
    values: dict, message: str
) -> None:
    with pytest.raises(ValueError, match=message):
        made()(**values)


def test_a_gain_declared_twice_or_a_default_for_no_gain_is_refused() -> None:
    with pytest.raises(TypeError, match="two parts declare the gain 'speed'"):
        composed("Twice", "test", [SpeedGains, type("Other", (SpeedGains,), {})], __name__)
    with pytest.raises(TypeError, match="no part declares spead"):
        made(spead=1.0)
