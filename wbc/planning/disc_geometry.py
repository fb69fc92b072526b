"""Discs in the plane, for the way planner (wbc.planning.drive_planner): their common tangents, and
whether a segment or an arc keeps out of them."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from wbc.geometry.obstacles import Circle

Array = np.ndarray

TOUCH = 1e-7
"""How far a segment or a node may reach into a disc and still count as outside, m."""
TAU = 2.0 * math.pi


def segment_clear(a: Array, b: Array, obstacles: Sequence[Circle], clearance: float) -> bool:
    """The segment a-b keeps ``clearance`` from every obstacle's circle."""
    centres = np.array([(c.x, c.y) for c in obstacles], dtype=float).reshape(-1, 2)
    radii = np.array([c.radius + clearance for c in obstacles], dtype=float)
    return clear(np.asarray(a, dtype=float)[:2], np.asarray(b, dtype=float)[:2], centres, radii)


def bitangents(
    first: tuple[Array, float], second: tuple[Array, float]
) -> list[tuple[float, float]]:
    """The angles on each disc of their common tangents: outer (same angle on both), inner
    (opposite angles), those that exist."""
    (c1, r1), (c2, r2) = first, second
    offset = c2 - c1
    distance = float(np.hypot(*offset))
    theta = math.atan2(offset[1], offset[0])
    pairs = []
    if distance > abs(r1 - r2):
        alpha = math.acos((r1 - r2) / distance)
        pairs += [(theta + alpha, theta + alpha), (theta - alpha, theta - alpha)]
    if distance > r1 + r2:
        beta = math.acos((r1 + r2) / distance)
        pairs += [(theta + beta, theta + beta + math.pi), (theta - beta, theta - beta + math.pi)]
    return pairs


def clear(a: Array, b: Array, centres: Array, radii: Array) -> bool:
    """No disc's interior (centres (n, 2), radii (n,)) meets the segment a-b."""
    direction = b - a
    squared = float(direction @ direction)
    t = (
        np.zeros(len(radii))
        if squared == 0.0
        else np.clip((centres - a) @ direction / squared, 0.0, 1.0)
    )
    nearest = a + t[:, None] * direction - centres
    return bool(np.all(np.hypot(nearest[:, 0], nearest[:, 1]) >= radii - TOUCH))


def covered(
    centre: Array, radius: float, other: Array, other_radius: float
) -> tuple[float, float] | None:
    """The angles (from, width) of the circle (centre, radius) inside the other disc, or
    None where they do not meet."""
    offset = other - centre
    distance = float(np.hypot(*offset))
    if distance >= radius + other_radius or distance + other_radius <= radius:
        return None
    if distance + radius <= other_radius:
        return 0.0, TAU
    cosine = (radius**2 + distance**2 - other_radius**2) / (2.0 * radius * distance)
    half = math.acos(max(-1.0, min(1.0, cosine)))
    return (math.atan2(offset[1], offset[0]) - half) % TAU, 2.0 * half


def overlaps(start: float, sweep: float, interval: tuple[float, float]) -> bool:
    """The counter-clockwise arc (start, sweep) and the interval (from, width) share more than
    an end point."""
    begin, width = interval
    if width >= TAU:
        return True
    shift = (begin - start) % TAU
    return shift < sweep - TOUCH or shift + width > TAU + TOUCH
