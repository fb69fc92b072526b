"""Why the staging supervisor refuses a goal of another kind than a pose (a position, a
point...), which it passes on as it is (``components.supervisor``): a pose goal's plan says
why itself."""

from __future__ import annotations

import math

import numpy as np

from messages.goal import Goal
from wbc.planning.candidate import within
from wbc.planning.staging import StagingParams
from wbc.robot import MobileManipulator

Region = tuple[tuple[float, float, float], ...]
"""Where the base may stand, as half-planes a x + b y <= c: the scene's camera's sight
(``RobotSight.region``), or () for anywhere."""


def direct_refusal(request: Goal, q: np.ndarray, robot: MobileManipulator, region: Region) -> str:
    """Why ``request`` is refused at ``q``: its arm not the robot's, its target farther than a
    plan may cover, or outside ``region`` (where the camera cannot see the base); else empty."""
    if request.task == "pose":
        return ""
    if request.arm is not None and len(request.arm) != robot.arm_dof:
        return (
            f"the {request.task} goal's arm has {len(request.arm)} joints, the robot's "
            f"are {robot.arm_dof} ({', '.join(robot.joint_names)})"
        )
    x, y = request.position[:2] if request.task == "position" else request.point
    distance, limit = math.hypot(x - q[0], y - q[1]), StagingParams.max_distance
    if not distance <= limit:
        return (
            f"the {request.task} goal is {distance:.3g} m from the base, farther than "
            f"the {limit:g} m a goal may lie"
        )
    if region and not within(region, (x, y)):
        return (
            f"the {request.task} goal's ({x:.2f}, {y:.2f}) m lies where the camera "
            "cannot see the base (keep_in_view)"
        )
    return ""
