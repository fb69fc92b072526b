"""The wire format: round trips, image payloads, and every way a payload can be bad."""

from __future__ import annotations

import math
from typing import Any

import msgpack
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from messages import (
    FORMAT_TAG,
    CameraFrame,
    Clock,
    DecodeError,
    Goal,
    MarkerDetections,
    RobotState,
    decode,
    encode,
)
from messages.base import Message
from tests.messages.message_examples import EXAMPLES, IMAGE, POSITION_GOAL, STATE
from tests.messages.message_strategies import MESSAGES


def _fields(message: Message) -> dict[str, Any]:
    return msgpack.unpackb(encode(message))[2]


def _payload(type_name: str, fields: dict[str, Any], tag: Any = FORMAT_TAG) -> bytes:
    return msgpack.packb([tag, type_name, fields])


@pytest.mark.parametrize("message", EXAMPLES, ids=lambda m: type(m).__name__)
def test_every_example_survives_a_round_trip(message: Message) -> None:
    assert decode(encode(message), type(message)) == message


@pytest.mark.parametrize("message_type", MESSAGES, ids=lambda t: t.__name__)
@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_round_trip_is_exact(message_type: type[Message], data: st.DataObject) -> None:
    message = data.draw(MESSAGES[message_type])
    decoded = decode(encode(message), message_type)
    assert decoded == message
    assert type(decoded) is message_type


def test_parameter_values_keep_their_type() -> None:
    status = next(m for m in EXAMPLES if type(m).__name__ == "ComponentStatus")
    decoded = decode(encode(status), type(status))
    assert {k: type(v) for k, v in decoded.parameters.items()} == {
        "eta": float,
        "steps": int,
        "law": str,
        "warm_start": bool,
    }


def test_image_pixels_are_bit_exact_and_raw_on_the_wire() -> None:
    payload = encode(IMAGE)
    assert decode(payload, CameraFrame).data == IMAGE.data
    assert len(IMAGE.data) < len(payload) <= len(IMAGE.data) + 400
    assert IMAGE.data in payload


@pytest.mark.parametrize("pixels", [1, 255, 256, 4096, 4097, 65535, 65536, 70000])
def test_images_of_every_msgpack_bin_size_are_plain_msgpack(pixels: int) -> None:
    frame = IMAGE.model_copy(update={"width": pixels, "height": 1, "data": bytes(pixels)})
    payload = encode(frame)
    assert msgpack.unpackb(payload)[2]["data"] == frame.data
    assert decode(payload, CameraFrame) == frame


@settings(max_examples=30, deadline=None)
@given(frame=MESSAGES[CameraFrame])
def test_any_image_is_plain_msgpack(frame: CameraFrame) -> None:
    tag, type_name, fields = msgpack.unpackb(encode(frame), use_list=False)
    assert (tag, type_name) == (FORMAT_TAG, "CameraFrame")
    assert fields == frame.model_dump()


@pytest.mark.parametrize("wrap", [bytes, bytearray, memoryview])
def test_decode_takes_any_buffer(wrap: type) -> None:
    assert decode(wrap(encode(STATE)), RobotState) == STATE


@pytest.mark.parametrize(
    "payload",
    [b"", b"\xc1", b"hello world", b"\x93\x01\x02", msgpack.packb({"a": 1}), msgpack.packb([1, 2])],
)
def test_garbage_is_a_decode_error(payload: bytes) -> None:
    with pytest.raises(DecodeError, match=r"^robot/state: RobotState: not"):
        decode(payload, RobotState, key="robot/state")


@settings(max_examples=300)
@given(payload=st.binary(max_size=64))
def test_random_bytes_never_escape_as_another_exception(payload: bytes) -> None:
    with pytest.raises(DecodeError):
        decode(payload, RobotState)


def test_every_truncation_is_a_decode_error() -> None:
    payload = encode(STATE)
    for length in range(len(payload)):
        with pytest.raises(DecodeError):
            decode(payload[:length], RobotState)


@settings(max_examples=300)
@given(position=st.integers(min_value=0), value=st.integers(0, 255))
def test_a_corrupted_byte_gives_an_error_or_a_whole_valid_message(
    position: int, value: int
) -> None:
    payload = bytearray(encode(STATE))
    payload[position % len(payload)] = value
    try:
        decoded = decode(payload, RobotState)
    except DecodeError:
        return
    assert RobotState.model_validate(decoded.model_dump()) == decoded


def test_another_wire_version_is_refused_by_name() -> None:
    with pytest.raises(DecodeError, match="'parsimony/2' is not supported") as caught:
        decode(_payload("RobotState", _fields(STATE), tag="parsimony/2"), RobotState)
    assert caught.value.field == ""


def test_a_foreign_tag_is_refused() -> None:
    with pytest.raises(DecodeError, match="not a parsimony message"):
        decode(_payload("RobotState", _fields(STATE), tag=1), RobotState)


def test_another_type_is_refused_with_both_names() -> None:
    with pytest.raises(DecodeError) as caught:
        decode(encode(Clock(stamp_ns=5)), RobotState, key="sim/robot/state")
    assert str(caught.value) == "sim/robot/state: RobotState: payload holds a 'Clock'"
    assert (caught.value.key, caught.value.type_name) == ("sim/robot/state", "RobotState")


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_non_finite_joint_names_the_field(bad: float) -> None:
    fields = _fields(STATE)
    fields["arm_joints"][2] = bad
    with pytest.raises(DecodeError) as caught:
        decode(_payload("RobotState", fields), RobotState, key="robot/state")
    assert str(caught.value) == (
        "robot/state: RobotState.arm_joints.2: Input should be a finite number"
    )
    assert caught.value.field == "arm_joints.2"


def test_a_non_finite_value_deep_in_a_list_of_models_names_the_path() -> None:
    detections = next(m for m in EXAMPLES if isinstance(m, MarkerDetections))
    fields = _fields(detections)
    fields["markers"][0]["reprojection_error"] = math.nan
    with pytest.raises(DecodeError) as caught:
        decode(_payload("MarkerDetections", fields), MarkerDetections)
    assert caught.value.field == "markers.0.reprojection_error"


def test_an_extra_field_is_refused() -> None:
    fields = _fields(STATE) | {"speed": 1.0}
    with pytest.raises(DecodeError, match=r"RobotState\.speed: Extra inputs are not permitted"):
        decode(_payload("RobotState", fields), RobotState)


def test_an_extra_field_in_the_header_is_refused() -> None:
    fields = _fields(STATE)
    fields["header"]["extra"] = 0
    with pytest.raises(DecodeError) as caught:
        decode(_payload("RobotState", fields), RobotState)
    assert caught.value.field == "header.extra"


def test_a_missing_field_is_named() -> None:
    fields = _fields(STATE)
    del fields["valid"]
    with pytest.raises(DecodeError, match=r"RobotState\.valid: Field required"):
        decode(_payload("RobotState", fields), RobotState)


def test_strings_are_not_coerced_into_numbers() -> None:
    fields = _fields(STATE)
    fields["age_s"] = "0.5"
    with pytest.raises(DecodeError) as caught:
        decode(_payload("RobotState", fields), RobotState)
    assert caught.value.field == "age_s"


def test_a_model_level_violation_has_no_field() -> None:
    fields = _fields(POSITION_GOAL)
    fields["position"] = None
    with pytest.raises(DecodeError, match="a position task needs a position") as caught:
        decode(_payload("Goal", fields), Goal, key="control/goal")
    assert caught.value.field == ""


def test_several_faults_are_counted() -> None:
    fields = _fields(STATE)
    fields["base_pose"] = [math.nan, math.nan, 0.0]
    with pytest.raises(DecodeError, match=r"base_pose\.0: .* \(and 1 more\)$"):
        decode(_payload("RobotState", fields), RobotState)


def test_an_image_of_the_wrong_size_is_refused() -> None:
    fields = _fields(IMAGE)
    fields["data"] = fields["data"][:-1]
    with pytest.raises(DecodeError, match="expected 307200"):
        decode(_payload("CameraFrame", fields), CameraFrame)


def test_decode_error_is_a_value_error() -> None:
    assert issubclass(DecodeError, ValueError)
