"""The gains every obstacle term shares: which constraint keeps the base clear (5.28, the
vector-field inequality, 5.19 or none), its gain, the clearance and the lookahead point."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from wbc.gains import gain

ObstacleMode = Literal["border", "vector_field", "conservative", "off"]
"""The obstacle constraint: 5.28, the vector-field inequality, 5.19, or none."""


@dataclass(frozen=True)
class ObstacleGains:
    obstacle_mode: ObstacleMode = gain(
        "border",
        doc="obstacle constraint: 5.28 (border), the vector-field inequality d' >= -eta_d d "
            "(vector_field, wbc.constraints.obstacle_vector_field), 5.19 (conservative) or none")
    obstacle_gain: float = gain(2.0, low=1e-3, high=100.0,
                                doc="lambda of 5.26 (border), eta_d (vector_field), gain on the "
                                    "clearance (conservative), 1/s")
    obstacle_margin: float = gain(0.05, low=0.0, high=1.0,
                                  doc="extra clearance round each obstacle and the base, m")
    obstacle_lookahead: float = gain(0.1, low=0.0, high=1.0,
                                     doc="d: the border constraint acts on the point d ahead "
                                         "of the wheel axle, m")
