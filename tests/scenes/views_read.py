"""For the tests of views: a view read back with nothing but its own schema (the protobuf
FileDescriptorSet written beside it; a small wire-format reader, protobuf itself is not
installed), the frames it carries composed into poses, and the messages the tests draw."""

from __future__ import annotations

import math
import struct
from typing import Any

import numpy as np

from messages import topics
from messages.header import Header
from messages.state import RobotState
from profiles.deploy_files import ROBOT_FILE
from scenes.foxglove_views import View, Viewer
from wbc import dq
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
"""The robot every profile runs."""
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


def same_pose(a: np.ndarray, b: np.ndarray) -> bool:
    """The same pose (a unit dual quaternion and its negation are one)."""
    return bool(np.allclose(a, b, atol=1e-12) or np.allclose(a, -b, atol=1e-12))


def views(viewer: Viewer, key: str, topic: topics.Topic, message: Any) -> dict[str, View]:
    """The views ``viewer`` makes of ``message``, by channel suffix."""
    return {view.channel_suffix: view for view in viewer(topic.name, key, message)}
