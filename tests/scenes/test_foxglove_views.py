"""scenes.foxglove_views: each view decoded with nothing but its own schema (the protobuf
FileDescriptorSet written beside it, read by tests/scenes/views_read.py) carries the message's
data."""

from __future__ import annotations

import math
import random
from pathlib import Path

import numpy as np
import pytest
from foxglove import messages as fox
from mcap.reader import make_reader

from messages import topics
from messages.camera import CameraFrame
from messages.commands import BaseCommand
from messages.goal import Goal
from messages.header import Header
from messages.markers import MarkerDetection, MarkerDetections
from messages.state import RobotState
from messages.truth import SimTruth
from record.session_file import SessionWriter
from scenes.foxglove_views import View, carried, views_of
from tests.scenes.views_read import (
    ARM,
    HEADER,
    KEY,
    STAMP_NS,
    decode,
    pose_dq,
    pose_of,
    robot_state,
    transforms_of,
    vector,
)
from vision.images import jpeg
from wbc import dq


@pytest.mark.parametrize("encoding", ["mono8", "bgr8", "rgb8"])
def test_an_image_is_a_raw_image_with_the_same_bytes(encoding: str) -> None:
    width, height, channels = 32, 24, 1 if encoding == "mono8" else 3
    pixels = random.Random(encoding).randbytes(width * height * channels)
    frame = CameraFrame.model_validate(
        {
            "header": HEADER,
            "encoding": encoding,
            "width": width,
            "height": height,
            "data": pixels,
            "intrinsics": {"fx": 40.0, "fy": 40.0, "cx": 15.5, "cy": 11.5},
        }
    )
    (view,) = views_of(topics.CAMERA_IMAGE.name, "sim/camera/image", frame)
    assert view.schema_name == "foxglove.RawImage"
    assert view.schema_data == fox.RawImage.get_schema().data
    image = decode(view)
    assert image["data"] == pixels
    assert (image["width"], image["height"], image["encoding"]) == (width, height, encoding)
    assert (image["step"], image["frame_id"]) == (width * channels, "camera")
    assert (image["timestamp"]["seconds"], image["timestamp"]["nanos"]) == (
        1_700_000_000,
        123_456_789,
    )


def test_a_jpeg_frame_is_a_compressed_image_with_the_same_file() -> None:
    grey = np.random.default_rng(3).integers(0, 256, (24, 32), dtype=np.uint8)
    data = jpeg(grey, 90)
    frame = CameraFrame.model_validate(
        {
            "header": HEADER,
            "encoding": "jpeg",
            "width": 32,
            "height": 24,
            "data": data,
            "intrinsics": {"fx": 40.0, "fy": 40.0, "cx": 15.5, "cy": 11.5},
        }
    )
    (view,) = views_of(topics.CAMERA_IMAGE.name, "sim/camera/image", frame)
    assert (view.schema_name, view.carries) == ("foxglove.CompressedImage", "data")
    image = decode(view)
    assert (image["data"], image["format"], image["frame_id"]) == (data, "jpeg", "camera")
    assert carried(view.schema_name, view.data) == data


def test_a_robot_state_gives_the_base_and_end_effector_frames() -> None:
    (view,) = views_of(topics.ROBOT_STATE.name, KEY, robot_state())
    frames = transforms_of(view)
    assert set(frames) == {"estimate/base", "estimate/end_effector"}
    base, hand = frames["estimate/base"], frames["estimate/end_effector"]
    assert base["parent_frame_id"] == hand["parent_frame_id"] == "world"
    assert vector(base["translation"], "xyz") == [1.5, -2.0, 0.0]
    assert vector(base["rotation"], "xyzw") == pytest.approx([0, 0, math.sin(0.3), math.cos(0.3)])
    assert vector(hand["translation"], "xyz") == pytest.approx([0.7, 0.2, 0.45], abs=1e-12)
    half = math.sqrt(0.5)
    assert vector(hand["rotation"], "xyzw") == pytest.approx([0, 0, half, half], abs=1e-12)


def test_the_truth_stands_in_the_simulators_world_under_the_estimates() -> None:
    truth = SimTruth(
        header=HEADER,
        base_pose=(1.5, -2.0, 0.6),
        arm_joints=ARM,
        end_effector=pose_dq(0.0, (0.7, 0.2, 0.45)),
        contacts=0,
        in_contact=False,
        goal=pose_dq(0.3, (1.0, 0.5, 0.4)),
        reference_pose=(0.75, 0.85, 0.3),
    )
    (view,) = views_of(topics.SIM_TRUTH.name, "sim/sim/truth", truth)
    frames = transforms_of(view)
    assert set(frames) == {"truth/world", "truth/base", "truth/end_effector", "truth/goal"}
    assert frames["truth/world"]["parent_frame_id"] == "world"
    assert {frames[n]["parent_frame_id"] for n in frames if n != "truth/world"} == {"truth/world"}
    # F0 stands at (0.75, 0.85, 0.3) in the simulator's world: there is its origin.
    world = frames["truth/world"]
    f0 = pose_of(world)
    assert np.allclose(dq.translation(dq.conj(f0))[1:], [0.75, 0.85, 0.0], atol=1e-12)
    assert vector(frames["truth/base"]["translation"], "xyz") == [1.5, -2.0, 0.0]


def test_markers_are_frames_of_the_camera_and_placed_ones_of_the_world() -> None:
    seen = (
        MarkerDetection(id=3, pose=pose_dq(0.0, (0.1, 0.2, 2.5)), reprojection_error=0.3),
        MarkerDetection(id=7, pose=pose_dq(math.pi, (-0.4, 0.0, 2.4)), reprojection_error=0.5),
    )
    camera = Header(stamp_ns=STAMP_NS, frame="camera", seq=3, source="test")
    view, _ = views_of(
        topics.VISION_MARKERS.name,
        "sim/vision/markers",
        MarkerDetections(header=camera, markers=seen),
    )
    frames = transforms_of(view)
    assert set(frames) == {"marker_3", "marker_7"}
    assert {f["parent_frame_id"] for f in frames.values()} == {"camera"}
    assert vector(frames["marker_7"]["translation"], "xyz") == pytest.approx([-0.4, 0, 2.4])
    assert vector(frames["marker_7"]["rotation"], "xyzw") == pytest.approx([0, 0, 1, 0], abs=1e-12)
    empty = MarkerDetections(header=camera)
    assert views_of(topics.WORLD_MARKERS.name, "sim/world/markers", empty) == []
    # The estimator's markers, placed in F0, are frames of the world beside the truth's.
    (placed,) = views_of(
        topics.WORLD_MARKERS.name,
        "sim/world/markers",
        MarkerDetections(header=HEADER, markers=seen),
    )
    frames = transforms_of(placed)
    assert set(frames) == {"estimate/marker_3", "estimate/marker_7"}
    assert {f["parent_frame_id"] for f in frames.values()} == {"world"}


def test_a_pose_goal_is_a_frame_and_a_position_goal_has_no_view() -> None:
    goal = Goal(header=HEADER, task="pose", pose=pose_dq(0.5, (0.3, -0.1, 0.6)))
    (view,) = views_of(topics.CONTROL_GOAL.name, "sim/control/goal", goal)
    frame = transforms_of(view)["goal"]
    assert frame["parent_frame_id"] == "world"
    assert vector(frame["translation"], "xyz") == pytest.approx([0.3, -0.1, 0.6])
    position = Goal(header=HEADER, task="position", position=(0.3, -0.1, 0.6))
    assert views_of(topics.CONTROL_GOAL.name, "sim/control/goal", position) == []


def test_topics_without_a_well_known_schema_have_no_view() -> None:
    command = BaseCommand(
        header=HEADER, forward_velocity=0.1, angular_velocity=0.2, left_wheel=0.07, right_wheel=0.13
    )
    assert views_of(topics.BASE_COMMAND.name, "sim/base/command", command) == []


def test_views_go_beside_their_message_in_a_session_file(tmp_path: Path) -> None:
    state = RobotState(
        header=HEADER,
        base_pose=(1.0, 2.0, 0.0),
        arm_joints=(0.0, 0.0, 0.0, 0.0, 0.0),
        end_effector=pose_dq(0.0, (0.5, 0.0, 0.4)),
        valid=True,
        age_s=0.0,
    )
    path = tmp_path / "session.mcap"
    with SessionWriter(path) as writer:
        writer.write(KEY, state, views=True)
    with path.open("rb") as stream:
        read = {c.topic: (s, m) for s, c, m in make_reader(stream).iter_messages()}
    schema, message = read[f"{KEY}/foxglove"]
    assert (schema.name, schema.encoding) == ("foxglove.FrameTransforms", "protobuf")
    assert message.log_time == STAMP_NS
    stored = View("foxglove", schema.name, schema.encoding, schema.data, "protobuf", message.data)
    hand = transforms_of(stored)["estimate/end_effector"]
    assert vector(hand["translation"], "xyz") == pytest.approx([0.5, 0.0, 0.4])
