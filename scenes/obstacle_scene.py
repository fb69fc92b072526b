"""The obstacles in Foxglove's 3-D panel, from the obstacles message alone (``Obstacles``), in
its header's frame (``world``: F0, where the estimate stands), so that a recording needs
nothing else to show them.

    circle (the base's)        a cylinder of the circle's radius from the floor to the
                               circle's ``height`` (the obstacle's top, where its marker lies),
                               ``CIRCLE_HEIGHT_M`` when the message does not say
    plane over a footprint     the solid as ``wbc.geometry.obstacles3d`` models it: under a table
                               top, the prism of the footprint from the floor up to the top (the
                               top face fairly opaque, the sides faint, the edges drawn); over
                               an underside, from it up ``UNBOUNDED_HEIGHT_M``
    plane without a footprint  (a wall, the floor) a thin box, ``WALL_SIDE_M`` square and
                               ``WALL_THICKNESS_M`` thick, its front face on the plane and its
                               body behind it, in the solid: a box shows which side is solid
                               where a quad would not, in one primitive. It is centred on the
                               point of the plane nearest (0, 0, ``WALL_SIDE_M`` / 2) above F0,
                               so a wall stands on the floor round F0
    cylinder (a pole)          a cylinder of its radius from the floor to its ``height``,
                               ``UNBOUNDED_HEIGHT_M`` tall when it has no top

Each solid carries its name as a label. The circles (``circle_scene``) and the solids
(``solid_scene``) go on channels of their own: the estimator sends the circles it sees with
every camera frame, while the declared solids seldom change, and are sent when they do
(``scenes.foxglove_views.Viewer``). Each update first deletes every entity of its channel, so
an obstacle that is gone disappears.
"""

from __future__ import annotations

import math

import numpy as np
from foxglove import messages as fox

from messages.obstacles import Cylinder, Obstacles, Plane
from scenes.foxglove_frames import replacing, timestamp
from scenes.robot_scene import at

CIRCLE_HEIGHT_M = 0.3
"""How tall a circle is drawn when the message gives no height (the demo's obstacles)."""
UNBOUNDED_HEIGHT_M = 1.5
"""How far a solid with no end upwards (a pole with no top, an underside) is drawn: above
the arm's reach."""
WALL_SIDE_M = 3.0
"""The side of the square a plane without a footprint is drawn as: the workspace round F0."""
WALL_THICKNESS_M = 0.03
OBSTACLE_RGB = (0.6, 0.4, 0.3)
"""Every obstacle's colour (here and in the report's figures): apart from the robots' (blue,
green, orange), and not the red of a penetration (``scenes.penetration_scene``)."""
OBSTACLE_COLOR = fox.Color(r=OBSTACLE_RGB[0], g=OBSTACLE_RGB[1], b=OBSTACLE_RGB[2], a=0.8)
FACE_COLOR = fox.Color(r=OBSTACLE_RGB[0], g=OBSTACLE_RGB[1], b=OBSTACLE_RGB[2], a=0.7)
"""A solid's face: the plane the robot keeps clear of."""
BODY_COLOR = fox.Color(r=OBSTACLE_RGB[0], g=OBSTACLE_RGB[1], b=OBSTACLE_RGB[2], a=0.2)
"""A solid's sides, faint: the arm's parts inside it stay visible."""
EDGE_COLOR = fox.Color(r=0.35, g=0.22, b=0.15, a=1.0)
EDGE_THICKNESS_PX = 2.0
LABEL_SIZE_PX = 14.0
LABEL_LIFT_M = 0.05
"""A label stands this far above (or in front of) its solid."""


def _label(name: str, position: np.ndarray) -> fox.TextPrimitive:
    return fox.TextPrimitive(
        pose=at(*map(float, position)),
        billboard=True,
        font_size=LABEL_SIZE_PX,
        scale_invariant=True,
        color=EDGE_COLOR,
        text=name,
    )


def _upright(
    x: float, y: float, radius: float, height: float, color: fox.Color
) -> fox.CylinderPrimitive:
    """A vertical cylinder from the floor to ``height``."""
    return fox.CylinderPrimitive(
        pose=at(x, y, height / 2),
        bottom_scale=1.0,
        top_scale=1.0,
        size=fox.Vector3(x=2 * radius, y=2 * radius, z=height),
        color=color,
    )


def circle_scene(obstacles: Obstacles) -> fox.SceneUpdate:
    """Every circle as a cylinder standing on the floor, after deleting the last ones."""
    stamp = timestamp(obstacles.header.stamp_ns)
    entities = [
        fox.SceneEntity(
            timestamp=stamp,
            frame_id=obstacles.header.frame,
            id=f"obstacle_{index}",
            cylinders=[_upright(c.x, c.y, c.radius, c.height or CIRCLE_HEIGHT_M, OBSTACLE_COLOR)],
        )
        for index, c in enumerate(obstacles.circles)
    ]
    return replacing(stamp, entities)


def solid_scene(obstacles: Obstacles) -> fox.SceneUpdate:
    """Every plane and cylinder of ``obstacles.solids`` (module docstring), after deleting the
    last ones."""
    stamp = timestamp(obstacles.header.stamp_ns)
    frame = obstacles.header.frame
    entities = [
        fox.SceneEntity(
            timestamp=stamp,
            frame_id=frame,
            id=f"plane_{index}",
            metadata=[fox.KeyValuePair(key="name", value=plane.name)],
            **plane_primitives(plane),
        )
        for index, plane in enumerate(obstacles.solids.planes)
    ]
    entities += [
        fox.SceneEntity(
            timestamp=stamp,
            frame_id=frame,
            id=f"cylinder_{index}",
            metadata=[fox.KeyValuePair(key="name", value=cylinder.name)],
            **cylinder_primitives(cylinder),
        )
        for index, cylinder in enumerate(obstacles.solids.cylinders)
    ]
    return replacing(stamp, entities)


def cylinder_primitives(cylinder: Cylinder) -> dict[str, list]:
    """A pole from the floor to its top (``UNBOUNDED_HEIGHT_M`` without one), its name over
    it."""
    height = cylinder.height if cylinder.height is not None else UNBOUNDED_HEIGHT_M
    label = np.array([cylinder.x, cylinder.y, height + LABEL_LIFT_M])
    return {
        "cylinders": [_upright(cylinder.x, cylinder.y, cylinder.radius, height, OBSTACLE_COLOR)],
        "texts": [_label(cylinder.name, label)],
    }


def plane_primitives(plane: Plane) -> dict[str, list]:
    """A plane's solid: the prism over its footprint, or a wall's thin box."""
    return _prism(plane) if plane.footprint else _wall(plane)


def prism_heights(plane: Plane) -> tuple[float, float, float]:
    """(the plane's height, the far end of the prism drawn, the side the solid lies on: +1
    under a top, -1 over an underside): the floor under a top above it (the top itself when it
    is not above the floor), ``UNBOUNDED_HEIGHT_M`` up from an underside."""
    side = plane.solid().side
    height = plane.offset * side
    if side > 0:
        return height, min(0.0, height), side
    return height, height + UNBOUNDED_HEIGHT_M, side


def _prism(plane: Plane) -> dict[str, list]:
    """The face at the plane's height over the footprint, the prism's sides to its far end,
    its edges, and its name over the face's centre."""
    footprint = np.array(plane.solid().footprint)  # counter-clockwise
    count = len(footprint)
    height, far, side = prism_heights(plane)
    ring = [fox.Point3(x=float(x), y=float(y), z=height) for x, y in footprint]
    far_ring = [fox.Point3(x=float(x), y=float(y), z=far) for x, y in footprint]
    fan = [i for j in range(1, count - 1) for i in (0, j, j + 1)]
    face = fox.TriangleListPrimitive(
        pose=at(0.0, 0.0, 0.0), points=ring, color=FACE_COLOR, indices=fan
    )
    following = [(i, (i + 1) % count) for i in range(count)]
    rim = [index for i, j in following for index in (i, j)]
    primitives: dict[str, list] = {"triangles": [face]}
    if far != height:
        sides = [
            index for i, j in following for index in (i, j, count + j, i, count + j, count + i)
        ]
        primitives["triangles"].append(
            fox.TriangleListPrimitive(
                pose=at(0.0, 0.0, 0.0), points=ring + far_ring, color=BODY_COLOR, indices=sides
            )
        )
        rim += [index for i in range(count) for index in (i, count + i)]
        rim += [count + index for i, j in following for index in (i, j)]
    primitives["lines"] = [
        fox.LinePrimitive(
            type=fox.LinePrimitiveLineType.LineList,
            pose=at(0.0, 0.0, 0.0),
            thickness=EDGE_THICKNESS_PX,
            scale_invariant=True,
            color=EDGE_COLOR,
            points=ring + far_ring,
            indices=rim,
        )
    ]
    centre = np.array([*footprint.mean(axis=0), height + side * LABEL_LIFT_M])
    primitives["texts"] = [_label(plane.name, centre)]
    return primitives


def wall_box(plane: Plane) -> tuple[np.ndarray, fox.Quaternion]:
    """The centre of a plane's box and its orientation, which turns the box's x axis onto the
    plane's normal n: q = (1 + x.n, x cross n) normalised (a half turn about z for n = -x)."""
    normal = np.array(plane.normal)
    middle = np.array([0.0, 0.0, WALL_SIDE_M / 2])
    foot = middle - (middle @ normal - plane.offset) * normal
    centre = foot - normal * WALL_THICKNESS_M / 2
    w, axis = 1.0 + normal[0], np.cross([1.0, 0.0, 0.0], normal)
    if w < 1e-9:
        return centre, fox.Quaternion(x=0.0, y=0.0, z=1.0, w=0.0)
    norm = math.sqrt(w * w + float(axis @ axis))
    return centre, fox.Quaternion(
        x=float(axis[0]) / norm, y=float(axis[1]) / norm, z=float(axis[2]) / norm, w=w / norm
    )


def _wall(plane: Plane) -> dict[str, list]:
    """A thin box with its front face on the plane, its name in front of its centre."""
    centre, orientation = wall_box(plane)
    box = fox.CubePrimitive(
        pose=at(*map(float, centre), orientation),
        color=FACE_COLOR,
        size=fox.Vector3(x=WALL_THICKNESS_M, y=WALL_SIDE_M, z=WALL_SIDE_M),
    )
    label = centre + np.array(plane.normal) * (WALL_THICKNESS_M / 2 + LABEL_LIFT_M)
    return {"cubes": [box], "texts": [_label(plane.name, label)]}
