"""The obstacles seen from above on a report's axes (``analysis.report``'s base path): the
base's circles, each table's (or underside's) footprint, each pole, each wall where it meets
the floor."""

from __future__ import annotations

from collections.abc import Sequence

from matplotlib.axes import Axes
from matplotlib.patches import Circle, Polygon

from messages.obstacles import Cylinder, Obstacles, Plane
from scenes.obstacle_scene import OBSTACLE_RGB

UNIT_TOLERANCE = 1e-9
"""Under this squared horizontal length a plane's normal is vertical."""


def draw_obstacles(ax: Axes, obstacles: Sequence[Obstacles]) -> None:
    """Every distinct circle and solid of ``obstacles`` (a session's messages) on ``ax``."""
    circles = {(c.x, c.y, c.radius) for message in obstacles for c in message.circles}
    for index, (cx, cy, radius) in enumerate(sorted(circles)):
        label = "obstacle" if index == 0 else None
        ax.add_patch(Circle((cx, cy), radius, color="red", alpha=0.4, label=label))
    planes, cylinders = _solids(obstacles)
    _solids_on_the_floor(ax, planes, cylinders)


def _solids(obstacles: Sequence[Obstacles]) -> tuple[list[Plane], list[Cylinder]]:
    """Every distinct plane and cylinder the obstacles messages carried."""
    planes = dict.fromkeys(p for message in obstacles for p in message.solids.planes)
    cylinders = dict.fromkeys(c for message in obstacles for c in message.solids.cylinders)
    return list(planes), list(cylinders)


def _solids_on_the_floor(ax: Axes, planes: Sequence[Plane], cylinders: Sequence[Cylinder]) -> None:
    """The solids seen from above: a table's (or an underside's) footprint, each pole's disc,
    each wall's line where it meets the floor (a horizontal plane without a footprint, which
    covers the whole floor, is not drawn); each labelled with its height."""
    for plane in planes:
        solid = plane.solid()
        nx, ny, _ = plane.normal
        if plane.footprint:
            kind = "top" if solid.side > 0 else "underside"
            ax.add_patch(
                Polygon(
                    solid.footprint,
                    closed=True,
                    color=OBSTACLE_RGB,
                    alpha=0.35,
                    hatch="//",
                    label=f"{plane.name} ({kind} at {plane.offset * solid.side:.2f} m)",
                )
            )
        elif nx * nx + ny * ny > UNIT_TOLERANCE:
            along = plane.offset / (nx * nx + ny * ny)  # the floor's point nearest F0
            ax.axline(
                (along * nx, along * ny),
                (along * nx - ny, along * ny + nx),
                color=OBSTACLE_RGB,
                linewidth=2.0,
                label=f"{plane.name} (at the floor)",
            )
    for cylinder in cylinders:
        top = "no top" if cylinder.height is None else f"{cylinder.height:.2f} m high"
        ax.add_patch(
            Circle(
                (cylinder.x, cylinder.y),
                cylinder.radius,
                color=OBSTACLE_RGB,
                alpha=0.6,
                hatch="xx",
                label=f"{cylinder.name} ({top})",
            )
        )
