"""A goal a Foxglove client sends on goal/request, checked like any goal before it is passed on.

Foxglove's 3-D panel (its publish-pose tool) sends a pose on the floor of the panel's fixed
frame as JSON: a ``foxglove.PoseInFrame`` or a ``foxglove.Pose``, or in the shape of ROS's
``geometry_msgs/PoseStamped`` (the schema versions of Foxglove give it on a source that is not
ROS), whose frame is in its header. It is taken as the
place of a goal marker F2, so the goal is the one the state estimator would measure there,
x_d = x_2 x_d^2 (eq. 6.3), with the scene's offset x_d^2 (the gripper over the bin), a pose
task. It is refused, with the reason, when it is larger than a goal can be
(``view.client_limits``), its JSON is not of those schemas (an object missing, a number
not finite, or out of range: a coordinate beyond ``FARTHEST_M``, checked before anything is
computed from it), its frame is not ``world`` (F0, where the estimate is), its orientation is
not a unit quaternion (within ``messages.base.UNIT_TOLERANCE``, as a goal's pose is checked),
the goal lies below the floor, or the supervisor would refuse it at once
(``wbc.planning.staging.refusal``: in an obstacle, farther than a plan may cover from the base). A
refusal repeats at most ``client_limits.ECHO_CHARS`` of any string the client sent.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence

import numpy as np
from pydantic import ValidationError

from messages.base import UNIT_TOLERANCE
from messages.goal import Goal
from messages.header import Header
from view.client_limits import ECHO_CHARS, GOAL_BYTES, cut, echo
from wbc import dq
from wbc.geometry.obstacles import Circle

IN_FRAME = ("foxglove.PoseInFrame",)
STAMPED = ("geometry_msgs/PoseStamped", "geometry_msgs/msg/PoseStamped")
SCHEMAS = (*IN_FRAME, "foxglove.Pose", *STAMPED)
"""What a client may publish on goal/request: a pose in a frame (``frame_id``, ``pose``), a
pose alone (``position``, ``orientation``), a stamped pose (``header.frame_id``, ``pose``)."""
ENCODING = "json"
"""How it may encode it."""
FRAME = "world"
"""The frame a PoseInFrame must be in (an empty frame is taken as it)."""
FARTHEST_M = 1000.0
"""No coordinate of a client's position lies farther from F0's origin, m. The supervisor
refuses a goal more than 10 m from the base anyway; this bound is checked first, so that no
arithmetic on a client's number overflows into a misleading refusal."""


class GoalRefused(ValueError):
    """A client's goal that is not passed on; the text says why."""


def _object(fields: dict, name: str, prefix: str = "") -> dict:
    """The object ``name`` of ``fields`` (``prefix`` names ``fields`` in a refusal)."""
    value = fields.get(name)
    if value is None:
        raise GoalRefused(f"{prefix}{name} is missing: a goal needs it")
    if not isinstance(value, dict):
        raise GoalRefused(f"{prefix}{name}: expected an object, got {echo(value)}")
    return value


def _number(fields: dict, name: str, prefix: str, limit: float, what: str) -> float:
    """The finite number ``name`` of ``fields``, within ``limit`` of 0 (``what`` says why);
    a missing one is 0, as protobuf's."""
    value = fields.get(name, 0.0)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise GoalRefused(f"{prefix}{name}: expected a number, got {echo(value)}")
    if isinstance(value, float) and not math.isfinite(value):
        raise GoalRefused(f"{prefix}{name}: expected a finite number, got {value}")
    if abs(value) > limit:
        raise GoalRefused(f"{prefix}{name} = {echo(value)} is out of range: {what}")
    return float(value)


def marker_pose(schema_name: str, data: bytes) -> np.ndarray:
    """The pose (a unit dual quaternion) a client's message of ``SCHEMAS`` gives, or
    ``GoalRefused``. Sizes and magnitudes are checked before anything is computed."""
    if schema_name not in SCHEMAS:
        raise GoalRefused(f"schema {echo(schema_name)}: goal/request takes {' or '.join(SCHEMAS)}")
    if len(data) > GOAL_BYTES:
        raise GoalRefused(f"a message of {len(data)} bytes: a goal is at most {GOAL_BYTES}")
    try:
        fields = json.loads(data)
    except RecursionError:
        raise GoalRefused("not a goal: its JSON is nested too deeply") from None
    except (UnicodeDecodeError, ValueError) as error:
        raise GoalRefused(f"not JSON: {cut(str(error), ECHO_CHARS)}") from None
    if not isinstance(fields, dict):
        raise GoalRefused(f"expected a {schema_name} object, got {echo(fields)}")
    prefix = ""
    if schema_name in (*IN_FRAME, *STAMPED):
        header = _object(fields, "header") if schema_name in STAMPED else fields
        frame = header.get("frame_id", "")
        if frame not in ("", FRAME):
            raise GoalRefused(f"frame_id {echo(frame)}: a goal is given in {FRAME!r} (F0)")
        fields, prefix = _object(fields, "pose"), "pose."
    far = f"a goal lies within {FARTHEST_M:g} m of F0"
    where = _object(fields, "position", prefix)
    position = [_number(where, axis, f"{prefix}position.", FARTHEST_M, far) for axis in "xyz"]
    unit = f"a unit quaternion's components lie in [-1, 1] (tolerance {UNIT_TOLERANCE:g})"
    turn = _object(fields, "orientation", prefix)
    w, x, y, z = (
        _number(turn, axis, f"{prefix}orientation.", 1.0 + UNIT_TOLERANCE, unit) for axis in "wxyz"
    )
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise GoalRefused(
            f"orientation has norm {norm:.9g}, expected 1 (tolerance {UNIT_TOLERANCE:g})"
        )
    return dq.pose(np.array([w, x, y, z]), np.array(position))


def client_goal(
    schema_name: str,
    data: bytes,
    offset: np.ndarray,
    header: Header,
    q_now: np.ndarray | None,
    obstacles: Sequence[Circle] = (),
) -> Goal:
    """The pose goal x_d = x_2 x_d^2 of a client's message, x_d^2 = ``offset``; checked against
    the robot at ``q_now`` (when the view knows it) and the ``obstacles``, or ``GoalRefused``."""
    pose = dq.mul(marker_pose(schema_name, data), offset)
    height = float(dq.translation(pose)[3])
    if height < 0.0:
        raise GoalRefused(f"the goal is {-height:.3f} m below the floor")
    if q_now is not None:
        # The planner (and its LP, SciPy) is imported by the first goal checked against a robot,
        # not by every command that imports this module.
        from wbc.planning.staging import StagingParams, refusal

        reason = refusal(q_now, pose, obstacles, StagingParams())
        if reason:
            raise GoalRefused(reason)
    try:
        return Goal(header=header, task="pose", pose=tuple(pose.tolist()))
    except ValidationError as error:
        raise GoalRefused(error.errors()[0]["msg"]) from None
