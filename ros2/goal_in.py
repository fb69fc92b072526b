"""A goal from ROS 2: a geometry_msgs/PoseStamped of the end effector, in CDR, in a frame of
the TF tree the bridge publishes, turned into Parsimony's pose goal in the world (F0).

It is refused (``Refused``, with the kind the bridge counts it under and the reason) when its
bytes are too many or not a PoseStamped's CDR (``malformed_cdr``), its frame is not in the tree
(``frame``: the tree is the one the latest robot state gives; without a state only ``world``
is), or its pose is not one (``goal``: a number not finite, an orientation not a unit
quaternion, a goal below the floor). The supervisor then checks it as any goal."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from pydantic import ValidationError

from messages.base import UNIT_TOLERANCE
from messages.goal import Goal
from messages.header import Header
from ros2.bridge_messages import GOAL_POSE
from ros2.wire import typestore
from wbc import dq

MAX_BYTES = 1024
"""The most bytes a PoseStamped may have (its frame name included)."""
ECHO_CHARS = 40
"""A refusal repeats at most this many characters of a frame name."""


class Refused(ValueError):
    """A goal not passed on: ``kind`` (its counter) and the reason."""

    def __init__(self, kind: str, reason: str) -> None:
        super().__init__(reason)
        self.kind = kind


def pose_stamped(data: bytes):
    """The PoseStamped of CDR ``data``, or ``Refused`` (``malformed_cdr``)."""
    if len(data) > MAX_BYTES:
        raise Refused("malformed_cdr", f"{len(data)} bytes: a goal is at most {MAX_BYTES}")
    try:
        return typestore().deserialize_cdr(data, GOAL_POSE[1])
    except Exception as error:  # rosbags raises many kinds on bytes it cannot parse
        raise Refused(
            "malformed_cdr", f"not a PoseStamped's CDR ({type(error).__name__})"
        ) from None


def _matrix(message) -> np.ndarray:
    """The 4x4 pose of a geometry_msgs/Pose, or ``Refused`` (``goal``)."""
    p, o = message.position, message.orientation
    values = (p.x, p.y, p.z, o.w, o.x, o.y, o.z)
    if not all(math.isfinite(v) for v in values):
        raise Refused("goal", "a number of the pose is not finite")
    norm = math.sqrt(o.w**2 + o.x**2 + o.y**2 + o.z**2)
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise Refused("goal", f"orientation has norm {norm:.9g}, expected 1")
    pose = np.eye(4)
    pose[:3, :3] = dq.rotation_matrix(np.array([o.w, o.x, o.y, o.z]))
    pose[:3, 3] = (p.x, p.y, p.z)
    return pose


def goal_of(data: bytes, frames: Mapping[str, np.ndarray], header: Header) -> Goal:
    """The pose goal in the world of PoseStamped ``data`` whose frame is one of ``frames``
    (name -> 4x4 pose in the world), or ``Refused``."""
    message = pose_stamped(data)
    frame = message.header.frame_id
    if frame not in frames:
        shown = frame[:ECHO_CHARS] + ("..." if len(frame) > ECHO_CHARS else "")
        raise Refused("frame", f"frame {shown!r} is not in the TF tree ({', '.join(frames)})")
    with np.errstate(all="ignore"):
        world = frames[frame] @ _matrix(message.pose)
    if not np.all(np.isfinite(world)):
        raise Refused("goal", "the goal is not finite in the world")
    if world[2, 3] < 0.0:
        raise Refused("goal", f"the goal is {-world[2, 3]:.3f} m below the floor")
    pose = dq.pose(dq.quaternion_of_matrix(world[:3, :3]), world[:3, 3])
    try:
        return Goal(header=header, task="pose", pose=tuple(float(v) for v in pose))
    except ValidationError as error:
        raise Refused("goal", error.errors()[0]["msg"]) from None
