"""The parts of the simulated robot inside a solid, drawn red over its truth in Foxglove's 3-D
panel, from the ground truth alone (``SimTruth``: the true configuration and the solids in the
simulator's world).

A collision part (``wbc.collision_model``) penetrates when its clearance from a solid is
negative (``wbc.geometry.arm_clearance.part_clearances``, what the simulator counts and the judge
reports). Each such point is drawn as its sphere, each segment as its capsule (a line as thick
as its diameter, a sphere at each end), at their true places in the simulator's world. The
truth says whether a part penetrates (``arm_penetrating``), so the parts are only looked for
then: a run that never touches a solid costs one empty scene.
"""

from __future__ import annotations

import numpy as np
from foxglove import messages as fox

from messages.truth import SimTruth
from scenes.foxglove_frames import replacing, timestamp
from scenes.robot_scene import at, point
from wbc.collision_model import point_positions
from wbc.geometry.arm_clearance import part_clearances
from wbc.robot import MobileManipulator

PENETRATION_COLOR = fox.Color(r=1.0, g=0.0, b=0.0, a=1.0)


def penetrating(robot: MobileManipulator, truth: SimTruth) -> tuple[str, ...]:
    """The names of the collision parts inside a solid now (none unless the truth says one
    is)."""
    if not truth.arm_penetrating or not robot.collision.names:
        return ()
    solids = truth.solids.solids()
    if not solids:
        return ()
    inside = part_clearances(robot, np.array(truth.configuration()), solids).min(axis=1) < 0.0
    return tuple(name for name, found in zip(robot.collision.names, inside, strict=True) if found)


def penetration_scene(
    robot: MobileManipulator, frame: str, truth: SimTruth, parts: tuple[str, ...]
) -> fox.SceneUpdate:
    """The ``parts`` (names) at the truth's configuration, in ``frame`` (the simulator's
    world), after deleting the last ones."""
    stamp = timestamp(truth.header.stamp_ns)
    model = robot.collision
    positions = point_positions(robot.frames(np.array(truth.configuration())), model)
    spheres = [
        _sphere(positions[i], p.radius) for i, p in enumerate(model.points) if p.name in parts
    ]
    lines = []
    for segment in model.segments:
        if segment.name in parts:
            ends = positions[[segment.start, segment.end]]
            spheres += [_sphere(end, segment.radius) for end in ends]
            lines.append(
                fox.LinePrimitive(
                    type=fox.LinePrimitiveLineType.LineStrip,
                    pose=at(0.0, 0.0, 0.0),
                    thickness=2 * segment.radius,
                    scale_invariant=False,
                    color=PENETRATION_COLOR,
                    points=[point(end) for end in ends],
                )
            )
    entities = (
        [
            fox.SceneEntity(
                timestamp=stamp,
                frame_id=frame,
                id="penetrating",
                metadata=[fox.KeyValuePair(key="parts", value=", ".join(parts))],
                spheres=spheres,
                lines=lines,
            )
        ]
        if parts
        else []
    )
    return replacing(stamp, entities)


def _sphere(centre: np.ndarray, radius: float) -> fox.SpherePrimitive:
    size = fox.Vector3(x=2 * radius, y=2 * radius, z=2 * radius)
    return fox.SpherePrimitive(pose=at(*map(float, centre)), size=size, color=PENETRATION_COLOR)
