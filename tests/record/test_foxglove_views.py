"""record.foxglove_views: each view decoded with nothing but its own schema (the protobuf
FileDescriptorSet written beside it; a small wire-format reader below, protobuf itself is not
installed) carries the message's data."""

from __future__ import annotations

import math
import random
import struct
from pathlib import Path
from typing import Any

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
from record.foxglove_views import View, carried, views_of
from record.session_file import SessionWriter
from vision.images import jpeg
from wbc import dq

STAMP_NS = 1_700_000_000_123_456_789
HEADER = Header(stamp_ns=STAMP_NS, frame="world", seq=3, source="test")
KEY = "sim/robot/state"

# ---- protobuf wire format, read with the schema's own descriptors -------------------------

REPEATED = 3
MESSAGE, STRING = 11, 9
FIXED_WIDTH = {1: "<d", 2: "<f", 6: "<Q", 7: "<I", 15: "<i", 16: "<q"}
"""struct formats of the fixed-width scalar types (double, float, fixed64, fixed32, sfixed)."""


def wire_fields(data: bytes) -> list[tuple[int, int, Any]]:
    """(field number, wire type, raw value) of every field of one protobuf message."""
    fields, at = [], 0

    def varint() -> int:
        nonlocal at
        value = shift = 0
        while True:
            byte = data[at]
            at += 1
            value |= (byte & 0x7F) << shift
            shift += 7
            if byte < 0x80:
                return value

    while at < len(data):
        tag = varint()
        number, wire = tag >> 3, tag & 7
        if wire == 0:
            value = varint()
        elif wire == 1:
            value, at = data[at : at + 8], at + 8
        elif wire == 2:
            length = varint()
            value, at = data[at : at + length], at + length
        elif wire == 5:
            value, at = data[at : at + 4], at + 4
        else:
            raise AssertionError(f"wire type {wire}")
        fields.append((number, wire, value))
    return fields


def descriptors(file_descriptor_set: bytes) -> dict[str, dict[int, tuple[str, int, int, str]]]:
    """Full message name -> field number -> (name, label, type, type name)."""
    found = {}

    def add(prefix: str, descriptor: bytes) -> None:
        parts = wire_fields(descriptor)
        name = f"{prefix}.{next(v.decode() for n, _, v in parts if n == 1)}"
        fields = {}
        for number, _, value in parts:
            if number == 2:  # FieldDescriptorProto: name 1, number 3, label 4, type 5, type 6
                field = {n: v for n, _, v in wire_fields(value)}
                fields[field[3]] = (
                    field[1].decode(),
                    field[4],
                    field[5],
                    field.get(6, b"").decode(),
                )
            elif number == 3:  # a nested DescriptorProto
                add(name, value)
        found[name] = fields

    for number, _, file in wire_fields(file_descriptor_set):
        assert number == 1
        parts = wire_fields(file)
        package = next((v.decode() for n, _, v in parts if n == 2), "")
        for n, _, value in parts:
            if n == 4:
                add(f".{package}" if package else "", value)
    return found


def decode(view: View) -> dict[str, Any]:
    """The view's message as a dict, read with its schema (absent fields are proto3 zeros)."""
    assert (view.schema_encoding, view.message_encoding) == ("protobuf", "protobuf")
    types = descriptors(view.schema_data)

    def read(type_name: str, data: bytes) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for number, wire, raw in wire_fields(data):
            name, label, kind, nested = types[type_name][number]
            if label == REPEATED and kind in FIXED_WIDTH and wire == 2:  # packed
                width = struct.calcsize(FIXED_WIDTH[kind])
                out.setdefault(name, []).extend(
                    struct.unpack(FIXED_WIDTH[kind], raw[i : i + width])[0]
                    for i in range(0, len(raw), width)
                )
                continue
            if kind == MESSAGE:
                value = read(nested, raw)
            elif kind == STRING:
                value = raw.decode()
            elif kind in FIXED_WIDTH:
                value = struct.unpack(FIXED_WIDTH[kind], raw)[0]
            else:
                value = raw  # bytes, or the integer of a varint
            if label == REPEATED:
                out.setdefault(name, []).append(value)
            else:
                out[name] = value
        return out

    return read(f".{view.schema_name}", view.data)


def vector(message: dict[str, Any], names: str) -> list[float]:
    return [message.get(n, 0.0) for n in names]


def pose_of(transform: dict[str, Any]) -> np.ndarray:
    """The pose (unit dual quaternion) of a FrameTransform as JSON."""
    rotation = np.array(vector(transform.get("rotation", {}), "wxyz"))
    return dq.pose(rotation, np.array(vector(transform.get("translation", {}), "xyz")))


def chain(frames: dict[str, dict[str, Any]], names: list[str], root: str) -> list[np.ndarray]:
    """Each named frame's pose in ``root``, composing every transform from its parent."""
    poses, pose, parent = [], dq.ONE.copy(), root
    for name in names:
        assert frames[name]["parent_frame_id"] == parent
        pose, parent = dq.mul(pose, pose_of(frames[name])), name
        poses.append(pose)
    return poses


# ---- the views ------------------------------------------------------------------------------


def pose_dq(angle_z: float, translation: tuple[float, float, float]) -> tuple[float, ...]:
    """The unit dual quaternion r + eps t r / 2 of a rotation about z, then a translation."""
    r = np.array([math.cos(angle_z / 2), 0.0, 0.0, math.sin(angle_z / 2)])
    t = np.array([0.0, *translation])
    return tuple(float(v) for v in (*r, *(0.5 * dq.qmul(t, r))))


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


def transforms_of(view: View) -> dict[str, dict[str, Any]]:
    assert view.schema_name == "foxglove.FrameTransforms"
    return {t["child_frame_id"]: t for t in decode(view)["transforms"]}


ARM = (0.1, -0.2, 0.3, -0.4, 0.5)


def robot_state(seq: int = 3) -> RobotState:
    header = Header(stamp_ns=STAMP_NS, frame="world", seq=seq, source="test")
    return RobotState(
        header=header,
        base_pose=(1.5, -2.0, 0.6),
        arm_joints=ARM,
        end_effector=pose_dq(math.pi / 2, (0.7, 0.2, 0.45)),
        valid=True,
        age_s=0.01,
    )


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
