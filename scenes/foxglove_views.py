"""The project's messages in Foxglove's well-known schemas, so that Foxglove's Image and 3D
panels open a recording (or a live view) with no plugin:

    CameraFrame            -> foxglove.CompressedImage  frame "camera", the same bytes: a JPEG
                              or foxglove.RawImage      as it is, raw pixels as they are; the view
                                                        alone carries them (``carries``)
    RobotState             -> foxglove.FrameTransforms  world -> estimate/base -> link_0..link_5
                                                        (with the robot description, else the
                                                        base alone), world ->
                                                        estimate/end_effector
                           -> foxglove.SceneUpdate      the robot's model (``model``)
    SimTruth               -> foxglove.FrameTransforms  world -> truth/world (the simulator's,
                                                        where F0 stands at ``reference_pose``)
                                                        -> truth/base ..., truth/end_effector,
                                                        truth/goal
                           -> foxglove.SceneUpdate      the robot's model (``model``)
                           -> foxglove.SceneUpdate      the parts inside a solid, red
                                                        (``penetrations``)
    MarkerDetections       -> foxglove.FrameTransforms  camera -> marker_<id> (vision/markers),
                                                        world -> estimate/marker_<id>
                                                        (world/markers)
                           -> foxglove.ImageAnnotations each marker's corners and id on the
                                                        image (vision/markers, ``annotations``)
    Goal (pose task)       -> foxglove.FrameTransforms  world -> goal (control/goal, goal/request),
                                                        world -> estimate/goal (world/goal)
    Obstacles              -> foxglove.SceneUpdate      one cylinder per circle, in the
                                                        message's frame ("world")
                           -> foxglove.SceneUpdate      its planes and cylinders in 3-D
                                                        (``solids``)
    SupervisorStatus       -> foxglove.FrameTransforms  world -> candidate/base -> ... (its
                                                        staging candidate)
                           -> foxglove.SceneUpdate      its way and the candidate's ghost
                                                        (``scene``)

The robot, its frames and its model are ``scenes.robot_scene``'s; the plan's
``scenes.plan_views``'; the annotations ``scenes.marker_annotations``'; the obstacles'
``scenes.obstacle_scene``'; the penetrations' ``scenes.penetration_scene``'. Each view is
protobuf, encoded by foxglove-sdk with its schema, and goes on the channel ``<key>/<suffix>``
(``View.channel``): ``foxglove`` for the transforms, images and circles, the name above for
the others, so no two views of a key share a channel.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from foxglove import messages as fox

from messages import topics
from messages.camera import CHANNELS, COMPRESSED, CameraFrame
from messages.goal import Goal
from messages.markers import MarkerDetections
from messages.obstacles import Obstacles
from messages.state import RobotState
from messages.supervisor import SupervisorStatus
from messages.truth import SimTruth
from scenes.foxglove_frames import planar_transform, pose_transform, timestamp
from scenes.marker_annotations import marker_annotations
from scenes.obstacle_scene import circle_scene, solid_scene
from scenes.penetration_scene import penetrating, penetration_scene
from scenes.plan_views import CANDIDATE_COLOR, CANDIDATE_PREFIX, plan_scene, plan_transforms
from scenes.robot_scene import RobotDrawing
from wbc.planar import inverse
from wbc.robot import MobileManipulator

CHANNEL_SUFFIX = "foxglove"
"""A view of the message on key K goes on the channel ``K/foxglove`` unless it says another."""
MODEL_SUFFIX, ANNOTATIONS_SUFFIX, SCENE_SUFFIX = "model", "annotations", "scene"
"""The channels of a robot's model, a frame's marker annotations, the supervisor's plan."""
SOLIDS_SUFFIX, PENETRATIONS_SUFFIX = "solids", "penetrations"
"""The channels of the obstacles in 3-D and of the robot's parts inside them."""
MODEL_EVERY = 25
"""A robot's model goes with one state in this many, by its sequence number (twice a second
at 50 Hz), and the supervisor's plan and the solids when they change and as often: a client
that joins late, or a file opened anywhere, has them within that; the frames move them in
between."""
ESTIMATE_COLOR = fox.Color(r=0.25, g=0.5, b=0.95, a=1.0)
TRUTH_COLOR = fox.Color(r=0.3, g=0.85, b=0.35, a=0.45)


def view_channel(key: str, suffix: str) -> str:
    """The channel a view with ``suffix`` of the messages on ``key`` goes on, beside it."""
    return f"{key}/{suffix}"


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
        return (
            view_channel(key, self.channel_suffix),
            self.schema_name,
            self.schema_encoding,
            self.schema_data,
            self.message_encoding,
            self.data,
        )


def view(message: Any, carries: str = "", suffix: str = CHANNEL_SUFFIX) -> View:
    """A foxglove-sdk message as a ``View`` on ``<key>/<suffix>``: its protobuf schema and
    bytes."""
    schema = type(message).get_schema()
    return View(
        suffix,
        schema.name,
        schema.encoding,
        bytes(schema.data),
        "protobuf",
        bytes(message.encode()),
        carries,
    )


def image_view(frame: CameraFrame) -> fox.CompressedImage | fox.RawImage:
    """A JPEG frame as it is, raw pixels as they are; the view carries them (``carries``)."""
    stamp = timestamp(frame.header.stamp_ns)
    if frame.encoding in COMPRESSED:
        return fox.CompressedImage(
            timestamp=stamp, frame_id="camera", data=frame.data, format=frame.encoding
        )
    step = frame.width * CHANNELS[frame.encoding]
    return fox.RawImage(
        timestamp=stamp,
        frame_id="camera",
        width=frame.width,
        height=frame.height,
        encoding=frame.encoding,
        step=step,
        data=frame.data,
    )


CARRIERS = (fox.CompressedImage, fox.RawImage)
"""The views that carry a field of their message (``View.carries``)."""


@functools.cache
def _protobuf_type(schema_name: str) -> type:
    """A carrier's protobuf class, built from the schema foxglove-sdk writes for it (protobuf
    imported here: only a reader of images needs it, not the recorder)."""
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

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


def marker_frames(prefix: str) -> Callable[[MarkerDetections], fox.FrameTransforms | None]:
    """Markers as frames, ``<header.frame> -> <prefix>marker_<id>``; none without markers."""

    def make(detections: MarkerDetections) -> fox.FrameTransforms | None:
        stamp, parent = detections.header.stamp_ns, detections.header.frame
        transforms = [
            pose_transform(parent, f"{prefix}marker_{m.id}", m.pose, stamp)
            for m in detections.markers
        ]
        return fox.FrameTransforms(transforms=transforms) if transforms else None

    return make


def goal_frame(frame: str) -> Callable[[Goal], fox.FrameTransforms | None]:
    """A pose goal as the frame ``world -> <frame>``; no frame for another task."""

    def make(goal: Goal) -> fox.FrameTransforms | None:
        if goal.pose is None:
            return None
        transform = pose_transform("world", frame, goal.pose, goal.header.stamp_ns)
        return fox.FrameTransforms(transforms=[transform])

    return make


def state_frames(drawing: RobotDrawing | None, state: RobotState) -> fox.FrameTransforms:
    """The estimate's frames: its base and links (with a robot to draw, else the base alone)
    and the end effector as the estimator gives it."""
    stamp = state.header.stamp_ns
    end_effector = pose_transform("world", "estimate/end_effector", state.end_effector, stamp)
    if drawing is None:
        base = planar_transform("world", "estimate/base", state.base_pose, stamp)
        return fox.FrameTransforms(transforms=[base, end_effector])
    q = drawing.configuration(state)
    return fox.FrameTransforms(transforms=[*drawing.transforms(q, stamp), end_effector])


def truth_frames(drawing: RobotDrawing | None, truth: SimTruth) -> fox.FrameTransforms:
    """The simulated robot in the simulator's world ``truth/world``, which hangs under the
    estimate's ``world`` (F0) where F0 stands in it, and the true goal."""
    stamp = truth.header.stamp_ns
    world = inverse(truth.reference_pose) if truth.reference_pose is not None else (0.0,) * 3
    parent = "truth/world"
    transforms = [planar_transform("world", parent, world, stamp)]
    if drawing is None:
        transforms.append(planar_transform(parent, "truth/base", truth.base_pose, stamp))
    else:
        transforms += drawing.transforms(drawing.configuration(truth), stamp)

    transforms.append(pose_transform(parent, "truth/end_effector", truth.end_effector, stamp))
    if truth.goal is not None:
        transforms.append(pose_transform(parent, "truth/goal", truth.goal, stamp))
    return fox.FrameTransforms(transforms=transforms)


def robot_model(drawing: RobotDrawing) -> Callable[[RobotState | SimTruth], fox.SceneUpdate | None]:
    """The robot's model, with one state in ``MODEL_EVERY``."""

    def make(state: RobotState | SimTruth) -> fox.SceneUpdate | None:
        if state.header.seq % MODEL_EVERY:
            return None
        return fox.SceneUpdate(entities=drawing.model(state.header.stamp_ns))

    return make


@dataclass(frozen=True)
class ViewMaker:
    """One view of a topic's messages: its channel suffix, its Foxglove type (None when the
    message decides it: an image's), and ``make(key, message)``, the foxglove-sdk message or
    None when this message has no such view; ``carries``: see ``View``."""

    suffix: str
    schema: type | None
    make: Callable[[str, Any], Any]
    carries: str = ""


def maker(
    suffix: str, schema: type | None, make: Callable[[Any], Any], carries: str = ""
) -> ViewMaker:
    """A ``ViewMaker`` of a view that depends on the message alone."""
    return ViewMaker(suffix, schema, lambda _key, message: make(message), carries)


def everything(suffix: str) -> bool:
    return True


class Viewer:
    """The views of every topic's messages (the table of the module docstring). Given the
    robot description, the estimate and the truth are drawn as robots and the supervisor's
    staging candidate as a ghost (``scenes.robot_scene``); without it, their bases and end
    effectors alone. A ``Viewer`` remembers the last plan, solids and penetrating parts of each
    key, to send them when they change: one writer or server uses one."""

    def __init__(self, robot: MobileManipulator | None = None) -> None:
        drawing = functools.partial(RobotDrawing, robot) if robot is not None else None
        estimate = drawing("estimate/", ESTIMATE_COLOR) if drawing else None
        truth = drawing("truth/", TRUTH_COLOR, "truth/world") if drawing else None
        self._candidate = drawing(CANDIDATE_PREFIX, CANDIDATE_COLOR) if drawing else None
        self._truth_world = truth.parent if truth else ""
        self._plans: dict[str, tuple] = {}
        self._solids: dict[str, tuple] = {}
        self._penetrating: dict[str, tuple[str, ...]] = {}
        frames, scene = fox.FrameTransforms, fox.SceneUpdate
        goal = maker(CHANNEL_SUFFIX, frames, goal_frame("goal"))
        self._makers: dict[str, tuple[ViewMaker, ...]] = {
            topics.CAMERA_IMAGE.name: (maker(CHANNEL_SUFFIX, None, image_view, "data"),),
            topics.ROBOT_STATE.name: (
                maker(CHANNEL_SUFFIX, frames, functools.partial(state_frames, estimate)),
                *([maker(MODEL_SUFFIX, scene, robot_model(estimate))] if estimate else []),
            ),
            topics.SIM_TRUTH.name: (
                maker(CHANNEL_SUFFIX, frames, functools.partial(truth_frames, truth)),
                *(
                    [
                        maker(MODEL_SUFFIX, scene, robot_model(truth)),
                        ViewMaker(
                            PENETRATIONS_SUFFIX, scene, functools.partial(self._penetrations, robot)
                        ),
                    ]
                    if truth
                    else []
                ),
            ),
            topics.VISION_MARKERS.name: (
                maker(CHANNEL_SUFFIX, frames, marker_frames("")),
                maker(ANNOTATIONS_SUFFIX, fox.ImageAnnotations, marker_annotations),
            ),
            topics.WORLD_MARKERS.name: (maker(CHANNEL_SUFFIX, frames, marker_frames("estimate/")),),
            topics.CONTROL_GOAL.name: (goal,),
            topics.GOAL_REQUEST.name: (goal,),
            topics.WORLD_GOAL.name: (maker(CHANNEL_SUFFIX, frames, goal_frame("estimate/goal")),),
            topics.WORLD_OBSTACLES.name: (
                maker(CHANNEL_SUFFIX, scene, circle_scene),
                ViewMaker(SOLIDS_SUFFIX, scene, self._solid_scene),
            ),
            topics.SUPERVISOR_STATUS.name: (
                maker(CHANNEL_SUFFIX, frames, self._plan_frames),
                ViewMaker(SCENE_SUFFIX, scene, self._plan_scene),
            ),
        }

    def __call__(
        self, topic_name: str, key: str, message: Any, wanted: Callable[[str], bool] = everything
    ) -> list[View]:
        """The well-known views of one message of ``topic_name`` whose suffix is ``wanted``;
        each goes on ``view.channel(key)``, beside the channel ``key`` the message is on."""
        found = []
        for each in self._makers.get(topic_name, ()):
            if wanted(each.suffix):
                made = each.make(key, message)
                if made is not None:
                    found.append(view(made, each.carries, each.suffix))
        return found

    def carrier(self, topic_name: str) -> tuple[str, str] | None:
        """The field of the message a view of ``topic_name`` carries, and that view's suffix
        (an image's pixels in its view), or None."""
        return next(
            ((m.carries, m.suffix) for m in self._makers.get(topic_name, ()) if m.carries), None
        )

    def channels(self, topic_name: str) -> list[tuple[str, type]]:
        """The suffix and Foxglove type of every view of ``topic_name`` whose type does not
        depend on the message: the channels a live view can open before their first view."""
        return [(m.suffix, m.schema) for m in self._makers.get(topic_name, ()) if m.schema]

    def _plan_frames(self, status: SupervisorStatus) -> fox.FrameTransforms | None:
        transforms = plan_transforms(self._candidate, status)
        return fox.FrameTransforms(transforms=transforms) if transforms else None

    def _plan_scene(self, key: str, status: SupervisorStatus) -> fox.SceneUpdate | None:
        """The plan's scene when it changed, and every ``MODEL_EVERY`` statuses."""
        plan = (status.candidate_base, status.candidate_arm, status.way)
        due = _due(self._plans, key, plan, status.header.seq)
        return plan_scene(self._candidate, status) if due else None

    def _solid_scene(self, key: str, obstacles: Obstacles) -> fox.SceneUpdate | None:
        """The solids when they (or their frame) changed, and every ``MODEL_EVERY``
        messages."""
        solids = (obstacles.header.frame, obstacles.solids)
        due = _due(self._solids, key, solids, obstacles.header.seq)
        return solid_scene(obstacles) if due else None

    def _penetrations(
        self, robot: MobileManipulator, key: str, truth: SimTruth
    ) -> fox.SceneUpdate | None:
        """The parts inside a solid, with every truth while there are some; an empty scene
        with the first truth and when they are gone."""
        parts = penetrating(robot, truth)
        if not parts and self._penetrating.get(key) == ():
            return None
        self._penetrating[key] = parts
        return penetration_scene(robot, self._truth_world, truth, parts)


def _due(sent: dict[str, tuple], key: str, value: tuple, seq: int) -> bool:
    """Whether to send ``value`` on ``key``: it differs from what was sent last, or ``seq``
    is a multiple of ``MODEL_EVERY``; if so it is noted as sent."""
    if sent.get(key) == value and seq % MODEL_EVERY:
        return False
    sent[key] = value
    return True


PLAIN = Viewer()
"""The views of a session with no robot description."""


def views_of(topic_name: str, key: str, message: Any) -> list[View]:
    """The well-known views of one message of ``topic_name`` with no robot description
    (``Viewer``)."""
    return PLAIN(topic_name, key, message)
