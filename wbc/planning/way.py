"""The base's way round the obstacles, as the way planner (``wbc.planning.drive_planner``) hands
it to the drive: tangent segments and arcs on the grown discs, and the waypoints the drive
steers to (each arc's circumscribed corners, then the target).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

Array = np.ndarray


@dataclass(frozen=True)
class Arc:
    """A piece of a way on a disc: from angle ``start`` through ``sweep`` (rad, > 0
    counter-clockwise) on radius ``radius`` about ``centre``."""

    centre: tuple[float, float]
    radius: float
    start: float
    sweep: float

    def corners(self, max_turn: float) -> list[Array]:
        """The corners of the polygon circumscribed about the arc, pieces of at most
        ``max_turn`` rad: the meeting points of the tangents at its ends and between them."""
        pieces = max(1, math.ceil(abs(self.sweep) / max_turn - 1e-9))
        step = self.sweep / pieces
        lifted = self.radius / math.cos(0.5 * step)
        angles = self.start + step * (np.arange(pieces) + 0.5)
        return [
            np.array([self.centre[0] + lifted * math.cos(a), self.centre[1] + lifted * math.sin(a)])
            for a in angles
        ]


@dataclass(frozen=True)
class Way:
    """The shortest way from ``start`` to ``target`` round the grown discs, or why none."""

    start: Array
    target: Array
    arcs: tuple[Arc, ...]
    length: float
    """The exact length of the tangent segments and arcs, m (inf without a way)."""
    reason: str
    """Why there is no way; empty when there is."""
    waypoints: tuple[Array, ...]
    """What the drive steers to, after the start: each arc's circumscribed corners, and the
    target last."""

    @property
    def found(self) -> bool:
        return not self.reason

    @property
    def turning(self) -> float:
        """The heading changes along the way, rad: a tangent path turns only on its arcs."""
        return float(sum(abs(arc.sweep) for arc in self.arcs))

    def first_bearing(self) -> float:
        """The direction of the way's first leg, rad."""
        return _bearing(self.start, self.waypoints[0])

    def last_bearing(self) -> float:
        """The direction of the way's last leg, into the target, rad."""
        return _bearing(self.waypoints[-2] if len(self.waypoints) > 1 else self.start, self.target)


def _bearing(a: Array, b: Array) -> float:
    return math.atan2(float(b[1] - a[1]), float(b[0] - a[0]))
