"""Obstacles in the plane of the base."""

from __future__ import annotations

from messages.base import Finite, Message, Positive
from messages.header import Header


class Circle(Message):
    """A circular obstacle: centre ``(x, y)`` and ``radius``, in m."""

    x: Finite
    y: Finite
    radius: Positive


class Obstacles(Message):
    """Every obstacle known, in the header's frame."""

    header: Header
    circles: tuple[Circle, ...] = ()
