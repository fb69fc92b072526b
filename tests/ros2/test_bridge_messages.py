"""The bridge's own ROS 2 messages: the camera's intrinsics as CameraInfo (K and P written
out by hand here), the ceiling camera on /tf_static, /clock, and the levels and messages
/diagnostics gives the controller, the supervisor and the bridge; each one serialises to CDR."""

from __future__ import annotations

import math

import numpy as np
import pytest

from messages.diagnostics import ControllerDiagnostics
from messages.supervisor import SupervisorStatus
from ros2 import bridge_messages as made
from ros2.wire import typestore
from tests.messages.message_examples import HEADER, IMAGE, QUARTER_TURN_SHIFTED

OK, WARN, ERROR = 0, 1, 2


def cdr_round_trip(message, msgtype: str):
    """``message`` serialised and read back: what a ROS 2 node receives."""
    store = typestore()
    return store.deserialize_cdr(bytes(store.serialize_cdr(message, msgtype)), msgtype)


def supervisor(**fields) -> SupervisorStatus:
    return SupervisorStatus(
        header=HEADER, candidate=0, plans=0, replans=0, stalls=0, **{"phase": "idle", **fields}
    )


def controller(status: str, reason: str = "") -> ControllerDiagnostics:
    return ControllerDiagnostics(
        header=HEADER,
        law="lp",
        status=status,
        reason=reason,
        nonzero=3,
        practical_nonzero=3,
        solve_time_us=200.0,
    )


def test_camera_info_is_the_pinhole_of_the_intrinsics_with_five_coefficients() -> None:
    info = cdr_round_trip(made.camera_info(IMAGE), made.CAMERA_INFO[1])
    # fx 525, fy 524.5, cx 319.5, cy 239.5; four coefficients given, plumb_bob takes five
    assert info.k.tolist() == [525.0, 0, 319.5, 0, 524.5, 239.5, 0, 0, 1]
    assert info.p.tolist() == [525.0, 0, 319.5, 0, 0, 524.5, 239.5, 0, 0, 0, 1, 0]
    assert info.d.tolist() == [0.1, -0.2, 0.0, 0.0, 0.0]
    assert info.r.tolist() == [1, 0, 0, 0, 1, 0, 0, 0, 1]
    assert (info.width, info.height, info.distortion_model) == (640, 480, "plumb_bob")
    assert info.header.frame_id == made.CAMERA_FRAME


def test_compressed_image_carries_the_jpeg_bytes_at_the_frames_stamp() -> None:
    jpeg = b"\xff\xd8" + bytes(range(10)) + b"\xff\xd9"
    image = cdr_round_trip(made.compressed_image(IMAGE, jpeg), made.COMPRESSED_IMAGE[1])
    assert bytes(image.data) == jpeg and image.format == "jpeg"
    assert (image.header.stamp.sec, image.header.stamp.nanosec) == (1_700_000_000, 123_456_789)


def test_clock_splits_nanoseconds_into_seconds_and_the_rest() -> None:
    message = cdr_round_trip(made.clock(12_000_000_007), made.CLOCK[1])
    assert (message.clock.sec, message.clock.nanosec) == (12, 7)


def test_static_transforms_place_the_camera_in_the_world_or_nothing() -> None:
    assert made.static_transforms(None, 1).transforms == []
    camera = cdr_round_trip(
        made.static_transforms(np.array(QUARTER_TURN_SHIFTED), 1), made.TF_STATIC[1]
    ).transforms[0]
    t, r = camera.transform.translation, camera.transform.rotation
    assert (camera.header.frame_id, camera.child_frame_id) == ("world", made.CAMERA_FRAME)
    assert (t.x, t.y, t.z) == pytest.approx((1.0, 2.0, 0.5))  # pi/4 about z, then (1, 2, 0.5)
    half = math.pi / 8
    assert abs(r.w * math.cos(half) + r.z * math.sin(half)) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("fields", "level", "message"),
    [
        ({"phase": "refused", "reason": "too far"}, ERROR, "refused: too far"),
        ({"phase": "aborted"}, ERROR, "aborted"),
        ({"phase": "unreachable", "warning": "no fix"}, ERROR, "unreachable"),
        ({"phase": "turn", "warning": "no fix for 2 s"}, WARN, "turn"),
        ({"phase": "turn"}, OK, "turn"),
    ],
)
def test_supervisor_status_is_error_for_a_goal_given_up_warn_for_a_warning(
    fields: dict, level: int, message: str
) -> None:
    status = made.supervisor_status(supervisor(**fields))
    assert (status.name, status.level, status.message) == ("parsimony/supervisor", level, message)


def test_a_status_lists_only_the_values_it_has_as_text() -> None:
    status = made.supervisor_status(supervisor(phase="turn", error_norm=0.25))
    values = {kv.key: kv.value for kv in status.values}
    assert values["phase"] == "turn" and values["error_norm"] == "0.25"
    assert values["refusals"] == "0"
    assert "last_refusal" in values  # an empty string is a value; None is none
    assert "state" in values
    no_norm = made.supervisor_status(supervisor(phase="turn"))
    assert "error_norm" not in {kv.key for kv in no_norm.values}


@pytest.mark.parametrize(
    ("status", "reason", "level", "message"),
    [
        ("optimal", "", OK, "optimal"),
        ("solved", "", OK, "solved"),
        ("infeasible", "rows clash", WARN, "infeasible: rows clash"),
    ],
)
def test_controller_status_is_ok_only_when_the_step_solved(
    status: str, reason: str, level: int, message: str
) -> None:
    said = made.controller_status(controller(status, reason))
    assert (said.name, said.level, said.message) == ("parsimony/controller", level, message)


def test_bridge_status_warns_once_anything_was_refused_and_lists_only_refusals() -> None:
    quiet = made.bridge_status({"refused.frame": 0, "goals_passed": 4}, "")
    assert (quiet.level, quiet.message) == (OK, "ok")
    assert [kv.key for kv in quiet.values] == ["refused.frame"]
    said = made.bridge_status({"refused.frame": 2, "goals_passed": 4}, "frame 'x' (frame)")
    assert (said.level, said.message) == (WARN, "frame 'x' (frame)")
    assert [(kv.key, kv.value) for kv in said.values] == [("refused.frame", "2")]


def test_a_diagnostic_array_of_every_status_serialises() -> None:
    statuses = [
        made.controller_status(controller("optimal")),
        made.supervisor_status(supervisor(phase="refused", reason="far")),
        made.bridge_status({"refused.goal": 1}, "below the floor"),
    ]
    array = cdr_round_trip(made.diagnostic_array(5, statuses), made.DIAGNOSTICS[1])
    assert [(s.name, s.level) for s in array.status] == [
        ("parsimony/controller", OK),
        ("parsimony/supervisor", ERROR),
        ("parsimony/ros2_bridge", WARN),
    ]
    assert array.header.stamp.nanosec == 5


def test_a_string_is_the_robot_description() -> None:
    assert cdr_round_trip(made.string("<robot/>"), made.ROBOT_DESCRIPTION[1]).data == "<robot/>"
