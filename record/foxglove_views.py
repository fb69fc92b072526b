"""The project's messages in Foxglove's well-known schemas, so that Foxglove's Image and 3D
panels open a recording (or a live view) with no plugin:

    CameraFrame            -> foxglove.CompressedImage  frame "camera", the same bytes: a JPEG
                              or foxglove.RawImage      as it is, raw pixels as they are; the view
                                                        alone carries them (``carries``)
    RobotState             -> foxglove.FrameTransforms  world -> estimate/base,
                                                        world -> estimate/end_effector
    SimTruth               -> foxglove.FrameTransforms  world -> truth/base, truth/end_effector
    MarkerDetections       -> foxglove.FrameTransforms  camera -> marker_<id> (vision/markers),
                                                        world -> estimate/marker_<id>
                                                        (world/markers)
    Goal (pose task)       -> foxglove.FrameTransforms  world -> goal (control/goal, goal/request)
    Obstacles              -> foxglove.SceneUpdate      one cylinder per circle, frame "world"

The base transform is the planar pose (x, y, phi): translation (x, y, 0), rotation phi about z.
A pose dual quaternion x gives translation(x) and rotation(x) (``wbc.dq``). Each view is
protobuf, encoded by foxglove-sdk with its schema, and goes on the channel
``<key>/foxglove`` (``View.channel``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from foxglove import messages as fox
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

from messages import topics
from messages.camera import CHANNELS, COMPRESSED, CameraFrame
from messages.goal import Goal
from messages.markers import MarkerDetections
from messages.obstacles import Obstacles
from messages.state import RobotState
from messages.truth import SimTruth
from wbc import dq

CHANNEL_SUFFIX = "foxglove"
"""A view of the message on key K goes on the channel ``K/foxglove``."""
OBSTACLE_HEIGHT_M = 0.3
"""How tall the 3D panel draws an obstacle, m."""
OBSTACLE_COLOR = fox.Color(r=0.8, g=0.2, b=0.2, a=0.8)


@dataclass(frozen=True)
class View:
    """One message in a well-known schema, ready for an MCAP channel or a live server."""

    channel_suffix: str
    schema_name: str
    schema_encoding: str
    schema_data: bytes
    message_encoding: str
    data: bytes
    carries: str = ""
    """The bytes field of the message that this view carries as it is (a frame's pixels in its
    RawImage): a file or a live view then sends it here alone (``carried``)."""

    def channel(self, key: str) -> tuple[str, str, str, bytes, str, bytes]:
        """The channel, schema, message encoding and data of the view of the message on
        ``key`` (``record.session_file.Entry``)."""
        return (f"{key}/{self.channel_suffix}", self.schema_name, self.schema_encoding,
                self.schema_data, self.message_encoding, self.data)  # fmt: skip


def view(message: Any, carries: str = "") -> View:
    """A foxglove-sdk message as a ``View``: its protobuf schema and bytes."""
    schema = type(message).get_schema()
    return View(CHANNEL_SUFFIX, schema.name, schema.encoding, bytes(schema.data), "protobuf",
                bytes(message.encode()), carries)  # fmt: skip


def timestamp(stamp_ns: int) -> fox.Timestamp:
    return fox.Timestamp(stamp_ns // 1_000_000_000, stamp_ns % 1_000_000_000)


def planar_transform(
    parent: str, child: str, base_pose: tuple[float, ...], stamp_ns: int
) -> fox.FrameTransform:
    """The transform of a planar pose (x, y, phi): translation (x, y, 0), phi about z."""
    x, y, phi = base_pose
    return fox.FrameTransform(
        timestamp=timestamp(stamp_ns), parent_frame_id=parent, child_frame_id=child,
        translation=fox.Vector3(x=x, y=y, z=0.0),
        rotation=fox.Quaternion(x=0.0, y=0.0, z=math.sin(phi / 2), w=math.cos(phi / 2)),
    )  # fmt: skip


def pose_transform(
    parent: str, child: str, pose: tuple[float, ...], stamp_ns: int
) -> fox.FrameTransform:
    """The transform of a unit dual quaternion: its translation and rotation."""
    x = np.asarray(pose, dtype=float)
    t, r = dq.translation(x), dq.rotation(x)
    return fox.FrameTransform(
        timestamp=timestamp(stamp_ns), parent_frame_id=parent, child_frame_id=child,
        translation=fox.Vector3(x=float(t[1]), y=float(t[2]), z=float(t[3])),
        rotation=fox.Quaternion(w=float(r[0]), x=float(r[1]), y=float(r[2]), z=float(r[3])),
    )  # fmt: skip


def image_views(frame: CameraFrame) -> list[View]:
    stamp = timestamp(frame.header.stamp_ns)
    if frame.encoding in COMPRESSED:
        image = fox.CompressedImage(timestamp=stamp, frame_id="camera", data=frame.data,
                                    format=frame.encoding)  # fmt: skip
    else:
        step = frame.width * CHANNELS[frame.encoding]
        image = fox.RawImage(timestamp=stamp, frame_id="camera", width=frame.width,
                             height=frame.height, encoding=frame.encoding, step=step,
                             data=frame.data)  # fmt: skip
    return [view(image, carries="data")]


CARRIERS = (fox.CompressedImage, fox.RawImage)
"""The views that carry a field of their message (``View.carries``)."""


@functools.cache
def _protobuf_type(schema_name: str) -> type:
    """A carrier's protobuf class, built from the schema foxglove-sdk writes for it."""
    schemas = {carrier.get_schema().name: carrier.get_schema() for carrier in CARRIERS}
    if schema_name not in schemas:
        raise ValueError(f"a {schema_name} carries no field of a project message")
    pool = descriptor_pool.DescriptorPool()
    for file in descriptor_pb2.FileDescriptorSet.FromString(bytes(schemas[schema_name].data)).file:
        pool.Add(file)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema_name))


def carried(schema_name: str, data: bytes) -> bytes:
    """The bytes a view carries for its message: an image's ``data``."""
    return bytes(_protobuf_type(schema_name).FromString(data).data)


def robot_views(prefix: str) -> Callable[[RobotState | SimTruth], list[View]]:
    """Views of a robot's state, its frames named ``<prefix>base`` and ``<prefix>end_effector``."""

    def views(state: RobotState | SimTruth) -> list[View]:
        stamp = state.header.stamp_ns
        return [view(fox.FrameTransforms(transforms=[
            planar_transform("world", prefix + "base", state.base_pose, stamp),
            pose_transform("world", prefix + "end_effector", state.end_effector, stamp),
        ]))]  # fmt: skip

    return views


def marker_views(prefix: str) -> Callable[[MarkerDetections], list[View]]:
    """Views of markers, ``<header.frame> -> <prefix>marker_<id>``."""

    def views(detections: MarkerDetections) -> list[View]:
        stamp, parent = detections.header.stamp_ns, detections.header.frame
        transforms = [pose_transform(parent, f"{prefix}marker_{m.id}", m.pose, stamp)
                      for m in detections.markers]  # fmt: skip
        return [view(fox.FrameTransforms(transforms=transforms))] if transforms else []

    return views


def goal_views(goal: Goal) -> list[View]:
    if goal.pose is None:
        return []
    transform = pose_transform("world", "goal", goal.pose, goal.header.stamp_ns)
    return [view(fox.FrameTransforms(transforms=[transform]))]


def obstacle_views(obstacles: Obstacles) -> list[View]:
    """Every obstacle as a cylinder standing on the floor; the update first deletes all the
    entities of the previous one, so obstacles that are gone disappear."""
    stamp = timestamp(obstacles.header.stamp_ns)
    entities = [fox.SceneEntity(
        timestamp=stamp, frame_id="world", id=f"obstacle_{index}",
        cylinders=[fox.CylinderPrimitive(
            pose=fox.Pose(position=fox.Vector3(x=c.x, y=c.y, z=OBSTACLE_HEIGHT_M / 2),
                          orientation=fox.Quaternion(w=1.0)),
            size=fox.Vector3(x=2 * c.radius, y=2 * c.radius, z=OBSTACLE_HEIGHT_M),
            bottom_scale=1.0, top_scale=1.0, color=OBSTACLE_COLOR,
        )],
    ) for index, c in enumerate(obstacles.circles)]  # fmt: skip
    deletion = fox.SceneEntityDeletion(timestamp=stamp, type=fox.SceneEntityDeletionType.All)
    return [view(fox.SceneUpdate(deletions=[deletion], entities=entities))]


VIEWS: dict[str, Callable[[Any], list[View]]] = {
    topics.CAMERA_IMAGE.name: image_views,
    topics.ROBOT_STATE.name: robot_views("estimate/"),
    topics.SIM_TRUTH.name: robot_views("truth/"),
    topics.VISION_MARKERS.name: marker_views(""),
    topics.WORLD_MARKERS.name: marker_views("estimate/"),
    topics.CONTROL_GOAL.name: goal_views,
    topics.GOAL_REQUEST.name: goal_views,
    topics.WORLD_OBSTACLES.name: obstacle_views,
}
"""Topic name -> the views of one of its messages; topics not named here have none."""


def views_of(topic_name: str, key: str, message: Any) -> list[View]:
    """The well-known views of one message of ``topic_name``; each goes on
    ``view.channel(key)``, beside the channel ``key`` the message itself is on."""
    make = VIEWS.get(topic_name)
    return make(message) if make is not None else []
