"""Circular obstacles in the plane of the base (section 5.5)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Circle:
    """An obstacle disc: centre (x, y) and radius, in metres, in the world frame F0."""

    x: float
    y: float
    radius: float
