"""A staging candidate: a configuration of the goal pose, the way there and what it costs; and
the plane geometry candidates are compared and kept clear by.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from wbc.geometry.obstacles import Circle
from wbc.planar import wrap
from wbc.planning.way import Way
from wbc.robot import BASE_DOF

Array = np.ndarray


@dataclass(frozen=True)
class Candidate:
    """A configuration of the goal pose and what getting there costs."""

    q: Array
    travel: float
    turning: float
    sigma: float
    score: float
    way: Way | None
    """The base's way from where the plan began to the staging point; None where the base
    stood near enough to go straight to the approach (``NEAR_HEADING``)."""
    final_leg: float
    """The straight leg into the pose: the staging point stands this far behind the base on
    its heading, m (ahead where negative)."""
    roomy: bool = True
    """The LP's obstacle constraint leaves the pose task alone at q_c and the turn at the
    staging point: the point ``slack`` ahead of q_c's axle keeps clearance + slack from
    every obstacle, and so does the staging point."""

    @property
    def base(self) -> Array:
        return self.q[:BASE_DOF]

    @property
    def arm(self) -> Array:
        return self.q[BASE_DOF:]

    @property
    def staging(self) -> Array:
        """Where the final leg starts."""
        return staging_point(self.base, self.final_leg)


def staging_point(base: Array, final_leg: float) -> Array:
    """Where the final straight leg into a base pose (x, y, phi) starts: ``final_leg`` behind
    it, on its heading (ahead where negative)."""
    x, y, phi = base
    return np.array([x - final_leg * math.cos(phi), y - final_leg * math.sin(phi)])


def clear_of(obstacles: Sequence[Circle], point: Array, body_radius: float) -> bool:
    return all(
        math.hypot(point[0] - c.x, point[1] - c.y) >= c.radius + body_radius for c in obstacles
    )


def within(region: Sequence[tuple[float, float, float]], *points: Array) -> bool:
    """Every point's (x, y) inside ``region`` (``StagingParams.region``): between two of
    them, the segment too, the region being convex."""
    return all(a * p[0] + b * p[1] <= c for p in points for a, b, c in region)


def same_kind(a: Array, b: Array) -> bool:
    """The bases within 0.1 m and 0.3 rad of each other."""
    return bool(math.hypot(*(a[:2] - b[:2])) < 0.1 and abs(wrap(a[2] - b[2])) < 0.3)


def same_configuration(a: Array, b: Array) -> bool:
    """Every entry within 0.02 (m or rad, headings wrapped)."""
    return bool(
        np.max(
            np.abs(
                np.concatenate((a[:2] - b[:2], [wrap(a[2] - b[2])], a[BASE_DOF:] - b[BASE_DOF:]))
            )
        )
        < 0.02
    )
