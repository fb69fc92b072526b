"""The gains every obstacle term shares: which constraint keeps the base clear (the
vector-field inequality by default, 5.28, 5.19 or none), its gain, the clearance and the
lookahead point.

The vector-field inequality is the default: it keeps u = 0 feasible, which 5.28 does not, and
on the obstacle experiment's set-ups, with the circulation term, it converged as often as 5.28
and kept the base 22-26 mm farther from the obstacle
(the study ``studies/files/obstacles.yaml``; docs/results/obstacles.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from wbc.laws.gains import gain

ObstacleMode = Literal["border", "vector_field", "conservative", "off"]
"""The obstacle constraint: 5.28, the vector-field inequality, 5.19, or none."""


@dataclass(frozen=True)
class ObstacleGains:
    obstacle_mode: ObstacleMode = gain(
        "vector_field",
        doc="obstacle constraint: the vector-field inequality d' >= -eta_d d (vector_field, "
        "wbc.laws.constraints.obstacle_vector_field), 5.28 (border), 5.19 (conservative) or none",
    )
    obstacle_gain: float = gain(
        2.0,
        low=1e-3,
        high=100.0,
        doc="lambda of 5.26 (border), eta_d (vector_field), gain on the "
        "clearance (conservative), 1/s",
    )
    obstacle_margin: float = gain(
        0.05, low=0.0, high=1.0, doc="extra clearance round each obstacle and the base, m"
    )
    obstacle_lookahead: float = gain(
        0.1,
        low=0.0,
        high=1.0,
        doc="d: 5.28 and the vector-field inequality act on the point d ahead of the wheel axle, m",
    )
