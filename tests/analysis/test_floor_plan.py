"""The obstacles seen from above on a report's axes (analysis/floor_plan.py): each distinct
circle once, a table's footprint, a wall's line on the floor, a pole's disc, each labelled."""

from __future__ import annotations

from matplotlib.figure import Figure

from analysis.floor_plan import draw_obstacles
from messages.header import Header
from messages.obstacles import Circle, Cylinder, Obstacles, Plane, Solids

HEADER = Header(stamp_ns=1, frame="world", seq=0, source="test")
TABLE = Plane(
    name="table",
    normal=(0.0, 0.0, 1.0),
    offset=0.3,
    footprint=((0.0, 0.0), (1.0, 0.0), (1.0, 0.5), (0.0, 0.5)),
)
WALL = Plane(name="wall", normal=(-1.0, 0.0, 0.0), offset=-2.0)
FLOOR = Plane(name="floor", normal=(0.0, 0.0, 1.0), offset=0.0)
POLE = Cylinder(name="pole", x=0.5, y=1.0, radius=0.05, height=0.6)


def test_every_distinct_obstacle_is_drawn_once_with_its_label() -> None:
    circle = Circle(x=1.0, y=-1.0, radius=0.2)
    solids = Solids(planes=(TABLE, WALL, FLOOR), cylinders=(POLE,))
    messages = [Obstacles(header=HEADER, circles=(circle,), solids=solids)] * 3
    ax = Figure().subplots()
    draw_obstacles(ax, messages)
    labels = [artist.get_label() for artist in [*ax.patches, *ax.lines]]
    assert sorted(labels) == [
        "obstacle",
        "pole (0.60 m high)",
        "table (top at 0.30 m)",
        "wall (at the floor)",
    ]  # the floor covers it all: not drawn
