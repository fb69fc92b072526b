"""A Foxglove layout for the live view (and the recordings) of a namespace, made with
foxglove-sdk's layout support (``foxglove.layouts``): it opens ready on the channels
``scenes.foxglove_views`` gives.

    +---------------------------+---------------------+
    | 3-D: the robot (estimate  | the camera image,   |
    | solid, truth ghost), the  | each marker's       |
    | goal, the plan, the       | outline and id      |
    | obstacles; publish        |                     |
    | pose -> goal/request      +---------------------+
    |                           | task error | nonzero|
    |                           +---------------------+
    |                           | arm joints          |
    +-------------+------------+-------------+--------+
    | controller's| supervisor | parameters  | teleop |
    | diagnostics |            |             |        |
    +-------------+------------+-------------+--------+

The arm joints' plot has a series per joint of the robot's description, by its name (none
without a description). The Teleop panel drives the base through the control station
(``view.station_teleop``) on teleop/command: up and down forward and back, left and right a
turn, the base stopped when a button is released.

Foxglove imports it as a file (Layouts, Import from file); its topics are keys of one
namespace, so each profile has its own (``parsimony layout PROFILE``).
"""

from __future__ import annotations

from collections.abc import Sequence

import foxglove.layouts as fl

from messages import topics
from scenes.foxglove_views import (
    ANNOTATIONS_SUFFIX,
    CHANNEL_SUFFIX,
    MODEL_SUFFIX,
    PENETRATIONS_SUFFIX,
    SCENE_SUFFIX,
    SOLIDS_SUFFIX,
    view_channel,
)
from view.station_teleop import PANEL_FORWARD_M_S, PANEL_RATE_HZ, PANEL_TURN_RAD_S

FIXED_FRAME = "world"
"""F0, the estimate's world, where the 3-D panel stands."""


def channel(namespace: str, topic: topics.Topic, suffix: str = "") -> str:
    """The live view's (and a recording's) channel of ``topic``, or of its view ``suffix``."""
    key = topic.key(namespace)
    return view_channel(key, suffix) if suffix else key


def path(namespace: str, topic: topics.Topic, field: str) -> str:
    """A message path of Foxglove: the topic quoted (its name has slashes), then the field."""
    return f'"{channel(namespace, topic)}".{field}'


def three_d(namespace: str) -> fl.ThreeDeePanel:
    """The robot, estimate and truth (its parts inside a solid red), the obstacles (circles and
    solids) and the plan, in F0; the publish-pose tool sends to goal/request."""
    scenes = [
        (topics.ROBOT_STATE, MODEL_SUFFIX),
        (topics.SIM_TRUTH, MODEL_SUFFIX),
        (topics.SIM_TRUTH, PENETRATIONS_SUFFIX),
        (topics.SUPERVISOR_STATUS, SCENE_SUFFIX),
        (topics.WORLD_OBSTACLES, CHANNEL_SUFFIX),
        (topics.WORLD_OBSTACLES, SOLIDS_SUFFIX),
    ]
    shown = {
        channel(namespace, topic, suffix): fl.BaseRendererSceneUpdateTopicSettings(visible=True)
        for topic, suffix in scenes
    }
    return fl.ThreeDeePanel(
        title="Robot",
        config=fl.ThreeDeeConfig(
            follow_tf=FIXED_FRAME,
            fixed_frame=FIXED_FRAME,
            follow_mode="follow-none",
            topics=shown,
            camera_state=fl.ThreeDeeCameraState(
                distance=4.0, perspective=True, phi=50.0, target=(0.5, 0.0, 0.0), theta_offset=45.0
            ),
            publish=fl.ThreeDeePublishSettings(
                type="pose", pose_topic=channel(namespace, topics.GOAL_REQUEST)
            ),
        ),
    )


def camera(namespace: str) -> fl.ImagePanel:
    """The image with each detected marker's outline and id."""
    annotations = channel(namespace, topics.VISION_MARKERS, ANNOTATIONS_SUFFIX)
    return fl.ImagePanel(
        title="Camera",
        config=fl.ImageConfig(
            image_mode=fl.ImageModeConfig(
                image_topic=channel(namespace, topics.CAMERA_IMAGE, CHANNEL_SUFFIX),
                annotations={annotations: fl.ImageAnnotationSettings(visible=True)},
            )
        ),
    )


def plot(namespace: str, title: str, fields: dict[str, str]) -> fl.PlotPanel:
    """The controller's diagnostics ``fields`` (label -> field) over time."""
    series = [
        fl.PlotSeries(value=path(namespace, topics.CONTROL_DIAGNOSTICS, field), label=label)
        for label, field in fields.items()
    ]
    return fl.PlotPanel(title=title, config=fl.PlotConfig(paths=series, show_legend=True))


def joints(namespace: str, joint_names: Sequence[str]) -> fl.PlotPanel:
    """The estimate's arm joints over time, a series per joint named as the robot's
    description names it (``robot/state``'s ``arm_joints``, index-aligned with the names)."""
    series = [
        fl.PlotSeries(value=path(namespace, topics.ROBOT_STATE, f"arm_joints[{i}]"), label=name)
        for i, name in enumerate(joint_names)
    ]
    return fl.PlotPanel(title="Arm joints", config=fl.PlotConfig(paths=series, show_legend=True))


def messages_of(namespace: str, topic: topics.Topic, title: str) -> fl.RawMessagesPanel:
    return fl.RawMessagesPanel(
        title=title, config=fl.RawMessagesConfig(topic_path=f'"{channel(namespace, topic)}"')
    )


def teleop(namespace: str) -> fl.TeleopPanel:
    """Foxglove's Teleop panel on the channel the control station takes for teleop/command."""

    def button(field: str, value: float) -> fl.TeleopButton:
        return fl.TeleopButton(field=field, value=value)

    return fl.TeleopPanel(
        title="Teleop",
        config=fl.TeleopConfig(
            topic=channel(namespace, topics.TELEOP_COMMAND),
            publish_rate=PANEL_RATE_HZ,
            up_button=button("linear-x", PANEL_FORWARD_M_S),
            down_button=button("linear-x", -PANEL_FORWARD_M_S),
            left_button=button("angular-z", PANEL_TURN_RAD_S),
            right_button=button("angular-z", -PANEL_TURN_RAD_S),
            stop_button=button("linear-x", 0.0),
            auto_send_stop_on_release=True,
        ),
    )


def split(direction: str, *items: tuple[float, fl.Content]) -> fl.SplitContainer:
    return fl.SplitContainer(
        direction=direction,
        items=[fl.SplitItem(proportion=share, content=content) for share, content in items],
    )


def layout(namespace: str, joint_names: Sequence[str] = ()) -> fl.Layout:
    """The layout of the module docstring, on the channels of ``namespace``, the arm joints'
    plot on ``joint_names`` (the robot's description's; none: no such plot)."""
    plots = split(
        "row",
        (1, plot(namespace, "Task error", {"||e||": "error_norm"})),
        (
            1,
            plot(
                namespace,
                "Nonzero entries of u",
                {"exact": "nonzero", "practical": "practical_nonzero"},
            ),
        ),
    )
    if joint_names:
        plots = split("column", (1, plots), (1, joints(namespace, joint_names)))
    top = split(
        "row", (3, three_d(namespace)), (2, split("column", (3, camera(namespace)), (2, plots)))
    )

    bottom = split(
        "row",
        (2, messages_of(namespace, topics.CONTROL_DIAGNOSTICS, "Controller")),
        (2, messages_of(namespace, topics.SUPERVISOR_STATUS, "Supervisor")),
        (2, fl.ParametersPanel(title="Parameters")),
        (1, teleop(namespace)),
    )
    return fl.Layout(content=split("column", (3, top), (2, bottom)))
