"""Obstacles: circles in the plane of the base, and planes and vertical cylinders in 3-D that
the robot's collision parts keep clear of (``wbc.geometry.obstacles3d``)."""

from __future__ import annotations

from pydantic import Field, model_validator

from messages.base import Finite, Message, Positive, Vector3
from messages.header import Header
from wbc.geometry import obstacles, obstacles3d


class Circle(Message):
    """A circular obstacle: centre ``(x, y)`` and ``radius``, in m, which the base clears at any
    height; its top's ``height`` above the floor (where its marker lies), m, where known."""

    x: Finite
    y: Finite
    radius: Positive
    height: Positive | None = None


MAX_CIRCLES = 256
"""The most obstacles one message may carry: each costs the LP a row and a step time."""
MAX_SOLIDS = 32
"""The most planes, and the most cylinders, one message may carry: each costs the LP a row
per collision part of the robot."""
MAX_FOOTPRINT = 64
"""The most vertices of a footprint."""


class Plane(Message):
    """The solid behind the plane <p, ``normal``> = ``offset`` (unit normal, m), over an
    optional convex ``footprint`` of (x, y) vertices (a horizontal plane's: a table top)."""

    name: str = Field(default="plane", max_length=64)
    normal: Vector3
    offset: Finite
    footprint: tuple[tuple[Finite, Finite], ...] = Field(default=(), max_length=MAX_FOOTPRINT)

    @model_validator(mode="after")
    def _a_solid(self) -> Plane:
        self.solid()  # ValueError naming the field: a unit normal, a convex footprint
        return self

    def solid(self) -> obstacles3d.Plane:
        return obstacles3d.Plane(self.normal, self.offset, self.footprint, self.name)

    @classmethod
    def of(cls, solid: obstacles3d.Plane) -> Plane:
        return cls(
            name=solid.name, normal=solid.normal, offset=solid.offset, footprint=solid.footprint
        )


class Cylinder(Message):
    """A vertical pole of ``radius`` round ``(x, y)`` from the floor to ``height`` (none: no
    top), m."""

    name: str = Field(default="cylinder", max_length=64)
    x: Finite
    y: Finite
    radius: Positive
    height: Positive | None = None

    @model_validator(mode="after")
    def _a_solid(self) -> Cylinder:
        self.solid()  # ValueError naming the field: every size within the scene's extent
        return self

    def solid(self) -> obstacles3d.Cylinder:
        return obstacles3d.Cylinder(self.x, self.y, self.radius, self.height, self.name)

    @classmethod
    def of(cls, solid: obstacles3d.Cylinder) -> Cylinder:
        return cls(name=solid.name, x=solid.x, y=solid.y, radius=solid.radius, height=solid.height)


class Solids(Message):
    """Planes and cylinders: what a scene declares, and what the obstacles message and the
    ground truth carry."""

    planes: tuple[Plane, ...] = Field(default=(), max_length=MAX_SOLIDS)
    cylinders: tuple[Cylinder, ...] = Field(default=(), max_length=MAX_SOLIDS)

    def solids(self) -> tuple[obstacles3d.Solid, ...]:
        """The ``wbc`` obstacles, planes first."""
        return (*(p.solid() for p in self.planes), *(c.solid() for c in self.cylinders))

    @classmethod
    def of(cls, solids: tuple[obstacles3d.Solid, ...]) -> Solids:
        return cls(
            planes=tuple(Plane.of(s) for s in solids if isinstance(s, obstacles3d.Plane)),
            cylinders=tuple(Cylinder.of(s) for s in solids if isinstance(s, obstacles3d.Cylinder)),
        )


class Obstacles(Message):
    """Every obstacle known, in the header's frame: circles for the base (at most
    ``MAX_CIRCLES``) and the ``solids`` in 3-D."""

    header: Header
    circles: tuple[Circle, ...] = Field(default=(), max_length=MAX_CIRCLES)
    solids: Solids = Solids()


def circles_of(message: Obstacles) -> tuple[obstacles.Circle, ...]:
    """The ``wbc`` circles a message carries, for the base."""
    return tuple(obstacles.Circle(c.x, c.y, c.radius) for c in message.circles)


def obstacles_of(message: Obstacles) -> tuple[obstacles.Obstacle, ...]:
    """The ``wbc`` obstacles a message carries: its circles, then its solids."""
    return (*circles_of(message), *message.solids.solids())
