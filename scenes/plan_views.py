"""The supervisor's plan in the 3-D panel, from its status (``SupervisorStatus``): the staging
candidate as a ghost of the robot, the base where it should stand and the arm as it should be
there (a ``RobotDrawing`` under ``candidate/``), and the way the base has still to go
(``way``) as a line on the floor through its points, a sphere on each. Every scene first
deletes the last one, so a plan that is gone (a new goal, a re-plan, unreachable) disappears
with it."""

from __future__ import annotations

import numpy as np
from foxglove import messages as fox

from messages.supervisor import SupervisorStatus
from scenes.foxglove_frames import replacing, timestamp
from scenes.robot_scene import RobotDrawing, at

CANDIDATE_PREFIX = "candidate/"
CANDIDATE_COLOR = fox.Color(r=1.0, g=0.6, b=0.1, a=0.35)
WAY_COLOR = fox.Color(r=1.0, g=0.6, b=0.1, a=1.0)
WAY_HEIGHT_M = 0.01
"""The way is drawn this far above the floor."""
WAY_THICKNESS_M = 0.015
WAY_POINT_M = 0.05
"""The diameter of a way point's sphere."""


def candidate_of(status: SupervisorStatus) -> np.ndarray | None:
    """The candidate's whole-body configuration q, if the status has one."""
    if status.candidate_base is None or status.candidate_arm is None:
        return None
    return np.array([*status.candidate_base, *status.candidate_arm])


def plan_transforms(
    drawing: RobotDrawing | None, status: SupervisorStatus
) -> list[fox.FrameTransform]:
    """The candidate's frames, if there is a candidate and a robot to draw."""
    q = candidate_of(status)
    if drawing is None or q is None:
        return []
    return drawing.transforms(q, status.header.stamp_ns)


def plan_scene(drawing: RobotDrawing | None, status: SupervisorStatus) -> fox.SceneUpdate:
    """The way and the candidate's ghost, after deleting the last plan's."""
    stamp = timestamp(status.header.stamp_ns)
    entities = []
    if status.way:
        points = [fox.Point3(x=x, y=y, z=WAY_HEIGHT_M) for x, y in status.way]
        size = fox.Vector3(x=WAY_POINT_M, y=WAY_POINT_M, z=WAY_POINT_M)
        entities.append(
            fox.SceneEntity(
                timestamp=stamp,
                frame_id="world",
                id="plan/way",
                lines=[
                    fox.LinePrimitive(
                        type=fox.LinePrimitiveLineType.LineStrip,
                        pose=at(0.0, 0.0, 0.0),
                        thickness=WAY_THICKNESS_M,
                        color=WAY_COLOR,
                        points=points,
                    )
                ],
                spheres=[
                    fox.SpherePrimitive(pose=at(x, y, WAY_HEIGHT_M), size=size, color=WAY_COLOR)
                    for x, y in status.way
                ],
            )
        )
    if drawing is not None and candidate_of(status) is not None:
        entities += drawing.model(status.header.stamp_ns)
    return replacing(stamp, entities)
