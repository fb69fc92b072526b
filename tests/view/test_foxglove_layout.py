"""The Foxglove layout of a namespace opens ready: every topic its panels name is a channel that a
recording (and so the live view) of that namespace holds, and `parsimony layout` gives it."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from components.control_step import TELEOP_TIMEOUT_S
from messages import topics
from messages.camera import CameraFrame
from messages.diagnostics import ControllerDiagnostics
from messages.header import Header
from messages.markers import MarkerDetection, MarkerDetections
from messages.obstacles import Circle, Obstacles
from messages.supervisor import SupervisorStatus
from messages.truth import SimTruth
from profiles.deploy_files import DEPLOY
from record.session_file import SessionWriter
from record.session_reader import info
from scenes.foxglove_views import Viewer
from tests.parsimony.in_process import run_in_process
from tests.scenes.views_read import ROBOT, pose_dq, robot_state
from tests.view.conftest import teleop_config
from view.foxglove_layout import layout
from view.station_teleop import teleop_topic
from vision.images import jpeg

NAMESPACE = "sim"
HEADER = Header(stamp_ns=1_000_000_000, frame="world", seq=0, source="test")


def one_of_each() -> list[tuple[topics.Topic, object]]:
    """A message of every topic the layout shows."""
    camera = HEADER.model_copy(update={"frame": "camera"})
    corners = ((10.0, 10.0), (20.0, 10.0), (20.0, 20.0), (10.0, 20.0))
    image = jpeg(np.zeros((48, 64), np.uint8), 90)
    return [
        (
            topics.CAMERA_IMAGE,
            CameraFrame.model_validate(
                {
                    "header": camera,
                    "encoding": "jpeg",
                    "width": 64,
                    "height": 48,
                    "data": image,
                    "intrinsics": {"fx": 60.0, "fy": 60.0, "cx": 31.5, "cy": 23.5},
                }
            ),
        ),
        (
            topics.VISION_MARKERS,
            MarkerDetections(
                header=camera,
                markers=(
                    MarkerDetection(
                        id=1,
                        pose=pose_dq(0.0, (0.0, 0.0, 2.5)),
                        reprojection_error=0.1,
                        corners=corners,
                    ),
                ),
            ),
        ),
        (topics.ROBOT_STATE, robot_state(seq=0)),
        (
            topics.SIM_TRUTH,
            SimTruth(
                header=HEADER,
                base_pose=(0.0, 0.0, 0.0),
                arm_joints=(0.0,) * 5,
                end_effector=pose_dq(0.0, (0.5, 0, 0.4)),
                contacts=0,
                in_contact=False,
            ),
        ),
        (
            topics.WORLD_OBSTACLES,
            Obstacles(header=HEADER, circles=(Circle(x=1.0, y=0.0, radius=0.1),)),
        ),
        (
            topics.SUPERVISOR_STATUS,
            SupervisorStatus(
                header=HEADER,
                phase="drive",
                candidate=1,
                plans=1,
                replans=0,
                stalls=0,
                way=((0.1, 0.2),),
            ),
        ),
        (
            topics.CONTROL_DIAGNOSTICS,
            ControllerDiagnostics(
                header=HEADER,
                law="lp",
                status="optimal",
                nonzero=7,
                practical_nonzero=6,
                solve_time_us=100.0,
                error_norm=math.pi,
            ),
        ),
    ]


def named_topics(node: object) -> set[str]:
    """Every topic a layout's panels name: topic settings, image and annotation topics, the
    publish topic, and the quoted topic of every message path."""
    found: set[str] = set()
    if isinstance(node, dict):
        for key, value in node.items():
            if key in ("topics", "annotations") and isinstance(value, dict):
                found |= set(value)
            elif key in ("imageTopic", "poseTopic", "topic"):
                found.add(value)
            elif key in ("value", "topicPath") and isinstance(value, str) and value[:1] == '"':
                found.add(value.split('"')[1])
            found |= named_topics(value)
    elif isinstance(node, list):
        for item in node:
            found |= named_topics(item)
    return found


def test_every_topic_the_layout_names_is_a_channel_of_the_namespace(tmp_path: Path) -> None:
    path = tmp_path / "session.mcap"
    with SessionWriter(path, viewer=Viewer(ROBOT)) as writer:
        for topic, message in one_of_each():
            writer.write(topic.key(NAMESPACE), message, views=True)
    channels = {c["key"] for c in info(path)["channels"]}
    document = json.loads(layout(NAMESPACE, ROBOT.joint_names).to_json())
    named = named_topics(document)
    publish = {f"{NAMESPACE}/goal/request", f"{NAMESPACE}/teleop/command"}  # the client's
    assert publish <= named
    assert named - publish <= channels, sorted(named - channels)
    assert {
        f"{NAMESPACE}/{suffix}"
        for suffix in (
            "camera/image/foxglove",
            "vision/markers/annotations",
            "robot/state/model",
            "sim/truth/model",
            "sim/truth/penetrations",
            "supervisor/status/scene",
            "world/obstacles/foxglove",
            "world/obstacles/solids",
            "control/diagnostics",
            "supervisor/status",
        )
    } <= named
    panels = json.dumps(document)
    for panel in ("ThreeDee", "Image", "Plot", "RawMessages", "Parameters", "Teleop"):
        assert f'"panelType":"{panel}"' in panels.replace(" ", "")


def test_parsimony_layout_prints_or_writes_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    profile = DEPLOY / "sim_station.yaml"
    code, printed, err = run_in_process(["layout", str(profile)], capsys)
    assert code == 0, err
    assert json.loads(printed) == json.loads(layout(NAMESPACE, ROBOT.joint_names).to_json())
    target = tmp_path / "station.json"
    assert run_in_process(["layout", str(profile), "-o", str(target)], capsys)[0] == 0
    assert json.loads(target.read_text()) == json.loads(printed)
    code, _, err = run_in_process(["layout", str(profile), "-o", str(target)], capsys)
    assert code == 2 and "--force" in err


def test_the_joints_plot_has_a_series_per_joint_of_the_description() -> None:
    document = json.loads(layout(NAMESPACE, ("shoulder", "elbow", "slide")).to_json())
    text = json.dumps(document)
    assert '"Arm joints"' in text
    for i, name in enumerate(("shoulder", "elbow", "slide")):
        assert f'robot/state\\".arm_joints[{i}]' in text and f'"{name}"' in text
    assert '"Arm joints"' not in json.dumps(json.loads(layout(NAMESPACE).to_json()))


def test_the_teleop_panel_drives_the_base_on_the_stations_teleop_channel() -> None:
    """Its topic is one the control station takes as teleop/command
    (``tests.view.test_station_teleop`` drives through it); a held button puts its twist
    several times within the controller's dead-man timeout, and a released one stops."""
    config = teleop_config(json.loads(layout(NAMESPACE).to_json()))
    assert config is not None
    assert config["topic"] == f"{NAMESPACE}/teleop/command"
    assert teleop_topic(config["topic"], NAMESPACE)
    assert 2.0 / config["publishRate"] < TELEOP_TIMEOUT_S
    buttons = {name: config[f"{name}Button"] for name in ("up", "down", "left", "right", "stop")}
    assert buttons["up"]["field"] == buttons["down"]["field"] == "linear-x"
    assert buttons["left"]["field"] == buttons["right"]["field"] == "angular-z"
    assert buttons["up"]["value"] > 0 > buttons["down"]["value"]
    assert buttons["left"]["value"] > 0 > buttons["right"]["value"]  # left: counterclockwise
    assert buttons["stop"]["value"] == 0 and config["autoSendStopOnRelease"]
