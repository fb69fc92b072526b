"""The project's messages in Foxglove's well-known schemas, so that Foxglove's Image, 3D and
Plot panels open a recording (or a live view) with no plugin.

    CameraFrame            -> foxglove.RawImage        (the same bytes: lossless)
    RobotState, SimTruth   -> foxglove.FrameTransforms world -> <prefix>base, <prefix>end_effector
    Goal (pose)            -> foxglove.FrameTransforms world -> goal
    MarkerDetections       -> foxglove.FrameTransforms camera -> marker_<id>
    Obstacles              -> foxglove.SceneUpdate     one cylinder per circle

Each view goes on the channel ``<key>/foxglove``, protobuf-encoded by foxglove-sdk.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from foxglove import messages as fox

from messages.camera import CHANNELS
from wbc import dq

OBSTACLE_HEIGHT_M = 0.3
"""How tall the 3D panel draws an obstacle."""
SUFFIX = "foxglove"


@dataclass(frozen=True)
class View:
    """One message in a well-known schema, ready for an MCAP channel or a live server."""

    schema_name: str
    schema_encoding: str
    schema_data: bytes
    message_encoding: str
    data: bytes
    message: object

    def channel(self, key: str) -> tuple[str, str, str, bytes, str, bytes]:
        """The arguments of ``SessionWriter.write_raw`` before the log time."""
        return (f"{key}/{SUFFIX}", self.schema_name, self.schema_encoding, self.schema_data,
                "protobuf", self.data)  # fmt: skip


def _view(message) -> View:
    schema = type(message).get_schema()
    return View(schema.name, schema.encoding, bytes(schema.data), "protobuf",
                bytes(message.encode()), message)  # fmt: skip


def _time(stamp_ns: int) -> fox.Timestamp:
    return fox.Timestamp(stamp_ns // 1_000_000_000, stamp_ns % 1_000_000_000)


def _planar(parent: str, child: str, x: float, y: float, phi: float, stamp_ns: int):
    return fox.FrameTransform(
        timestamp=_time(stamp_ns), parent_frame_id=parent, child_frame_id=child,
        translation=fox.Vector3(x=x, y=y, z=0.0),
        rotation=fox.Quaternion(x=0.0, y=0.0, z=math.sin(phi / 2), w=math.cos(phi / 2)),
    )  # fmt: skip


def _pose(parent: str, child: str, pose: tuple[float, ...], stamp_ns: int):
    x = np.array(pose)
    t, r = dq.translation(x)[1:], dq.rotation(x)
    return fox.FrameTransform(
        timestamp=_time(stamp_ns), parent_frame_id=parent, child_frame_id=child,
        translation=fox.Vector3(x=float(t[0]), y=float(t[1]), z=float(t[2])),
        rotation=fox.Quaternion(w=float(r[0]), x=float(r[1]), y=float(r[2]), z=float(r[3])),
    )  # fmt: skip


def views_of(topic_name: str, key: str, message) -> list[View]:
    """The well-known views of one message of ``topic_name`` (none for most topics)."""
    stamp = getattr(getattr(message, "header", None), "stamp_ns", 0)
    if topic_name == "camera/image":
        return [_view(fox.RawImage(
            timestamp=_time(stamp), frame_id="camera", width=message.width,
            height=message.height, encoding=message.encoding,
            step=message.width * CHANNELS[message.encoding], data=message.data,
        ))]  # fmt: skip
    if topic_name in ("robot/state", "sim/truth"):
        prefix = "truth/" if topic_name == "sim/truth" else "estimate/"
        return [_view(fox.FrameTransforms(transforms=[
            _planar("world", prefix + "base", *message.base_pose, stamp),
            _pose("world", prefix + "end_effector", message.end_effector, stamp),
        ]))]  # fmt: skip
    if topic_name == "control/goal" and message.pose is not None:
        return [_view(fox.FrameTransforms(transforms=[_pose("world", "goal", message.pose,
                                                            stamp)]))]  # fmt: skip
    if topic_name == "vision/markers":
        transforms = [_pose("camera", f"marker_{m.id}", m.pose, stamp) for m in message.markers]
        return [_view(fox.FrameTransforms(transforms=transforms))] if transforms else []
    if topic_name == "world/obstacles":
        entities = [fox.SceneEntity(
            timestamp=_time(stamp), frame_id="world", id=f"obstacle_{index}",
            cylinders=[fox.CylinderPrimitive(
                pose=fox.Pose(position=fox.Vector3(x=c.x, y=c.y, z=OBSTACLE_HEIGHT_M / 2),
                              orientation=fox.Quaternion(w=1.0)),
                size=fox.Vector3(x=2 * c.radius, y=2 * c.radius, z=OBSTACLE_HEIGHT_M),
                bottom_scale=1.0, top_scale=1.0, color=fox.Color(r=0.8, g=0.2, b=0.2, a=0.8),
            )],
        ) for index, c in enumerate(message.circles)]  # fmt: skip
        return [_view(fox.SceneUpdate(entities=entities))]
    return []
