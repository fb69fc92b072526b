"""Obstacles in the plane of the base."""

from __future__ import annotations

from pydantic import Field

from messages.base import Finite, Message, Positive
from messages.header import Header


class Circle(Message):
    """A circular obstacle: centre ``(x, y)`` and ``radius``, in m."""

    x: Finite
    y: Finite
    radius: Positive


MAX_CIRCLES = 256
"""The most obstacles one message may carry: each costs the LP a row and a step time."""


class Obstacles(Message):
    """Every obstacle known, in the header's frame (at most ``MAX_CIRCLES``)."""

    header: Header
    circles: tuple[Circle, ...] = Field(default=(), max_length=MAX_CIRCLES)
