"""Validation of the message models: what each one accepts and refuses."""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import given
from message_examples import EXAMPLES, HEADER, IMAGE, POSE_GOAL, QUARTER_TURN_SHIFTED, STATE
from message_strategies import unit_dual_quaternions
from pydantic import ValidationError

from messages import (
    IDENTITY_POSE,
    MESSAGE_TYPES,
    ArmCommand,
    CameraFrame,
    Circle,
    Goal,
    Header,
    JointStates,
    MarkerDetection,
    RobotState,
)
from messages.base import Message
from messages.obstacles import Cylinder, Plane, Solids
from wbc.geometry import obstacles3d


def _float_paths(value: Any, path: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    """Paths to every float inside a ``model_dump()``."""
    if isinstance(value, float):
        yield path
    elif isinstance(value, dict):
        for key, item in value.items():
            yield from _float_paths(item, (*path, key))
    elif isinstance(value, tuple | list):
        for index, item in enumerate(value):
            yield from _float_paths(item, (*path, index))


def _replaced(value: Any, path: tuple[Any, ...], new: float) -> Any:
    if not path:
        return new
    head, rest = path[0], path[1:]
    if isinstance(value, dict):
        return {**value, head: _replaced(value[head], rest, new)}
    return [_replaced(item, rest, new) if i == head else item for i, item in enumerate(value)]


def _non_finite_cases() -> Iterator[Any]:
    for message in EXAMPLES:
        for path in _float_paths(message.model_dump()):
            for bad in (math.nan, math.inf, -math.inf):
                name = ".".join(map(str, (type(message).__name__, *path)))
                yield pytest.param(message, path, bad, id=f"{name}={bad}")


def test_examples_cover_every_wire_type() -> None:
    assert {type(m) for m in EXAMPLES} == set(MESSAGE_TYPES)


@pytest.mark.parametrize(("message", "path", "bad"), list(_non_finite_cases()))
def test_every_float_of_every_message_must_be_finite(
    message: Message, path: tuple[Any, ...], bad: float
) -> None:
    fields = _replaced(message.model_dump(), path, bad)
    with pytest.raises(ValidationError) as caught:
        type(message).model_validate(fields)
    assert any(error["loc"][: len(path)] == path for error in caught.value.errors())


def test_messages_are_frozen() -> None:
    with pytest.raises(ValidationError, match="frozen"):
        STATE.valid = False  # type: ignore[misc]


def test_unknown_fields_are_refused() -> None:
    with pytest.raises(ValidationError, match="Extra inputs"):
        Circle(x=0, y=0, radius=1, colour="red")  # type: ignore[call-arg]


def test_header_counts_are_non_negative() -> None:
    with pytest.raises(ValidationError, match="stamp_ns"):
        Header(stamp_ns=-1, frame="world", seq=0, source="test")
    with pytest.raises(ValidationError, match="seq"):
        Header(stamp_ns=0, frame="world", seq=2**64, source="test")


def test_configuration_is_base_pose_then_arm_joints() -> None:
    assert STATE.configuration() == [1.0, 2.0, 0.3, 0.1, -0.2, 0.3, -0.4, 0.5]


@pytest.mark.parametrize("length", [1, 4, 7, 12])
def test_arm_joints_are_as_many_as_the_robot_names(length: int) -> None:
    names = tuple(f"joint_{i}" for i in range(length))
    state = RobotState.model_validate(
        STATE.model_dump() | {"arm_joints": [0.0] * length, "joint_names": names}
    )
    assert state.joint_names == names and len(state.configuration()) == 3 + length
    command = ArmCommand(header=HEADER, joint_velocities=(0.1,) * length, joint_names=names)
    assert command.joint_names == names


def test_joints_named_by_no_one_are_q1_to_qn() -> None:
    """A sender (or a recording) that names no joint: a DH table's default names."""
    fields = STATE.model_dump()
    del fields["joint_names"]
    assert RobotState.model_validate(fields | {"arm_joints": [0.0] * 3}).joint_names == (
        "q1",
        "q2",
        "q3",
    )
    assert ArmCommand(header=HEADER, joint_velocities=(0.0, 0.0)).joint_names == ("q1", "q2")


@pytest.mark.parametrize(
    ("fields", "complaint"),
    [
        ({"arm_joints": []}, "at least 1 item"),
        ({"joint_names": ("q1", "q2")}, "2 names, arm_joints 5 values"),
        ({"joint_names": ("a", "b", "c", "d", "a")}, "not unique"),
    ],
)
def test_joint_names_line_up_with_the_joints(fields: dict[str, Any], complaint: str) -> None:
    with pytest.raises(ValidationError, match=complaint):
        RobotState.model_validate(STATE.model_dump() | fields)
    command = {"joint_velocities": fields.get("arm_joints", (0.0,) * 5)}
    with pytest.raises(ValidationError, match=complaint.replace("arm_joints", "joint_velocities")):
        ArmCommand(
            header=HEADER, **command, **{k: v for k, v in fields.items() if k != "arm_joints"}
        )


@given(pose=unit_dual_quaternions())
def test_any_rigid_motion_is_a_valid_pose(pose: tuple[float, ...]) -> None:
    assert MarkerDetection(id=0, pose=pose, reprojection_error=0.0).pose == pose


@pytest.mark.parametrize(
    ("pose", "complaint"),
    [
        ((2.0, 0, 0, 0, 0, 0, 0, 0), "primary part has norm 2"),
        ((0.0,) * 8, "primary part has norm 0"),
        ((1.0, 0, 0, 0, 0.5, 0, 0, 0), "dual part of x\\*conj\\(x\\) is 1"),
        ((1.0, 0, 0, 0, 0, 0, 0), r"7\s+Field required"),
        ((1.0, 0, 0, 0, 0, 0, 0, 0, 0), "at most 8 items"),
    ],
)
def test_a_pose_must_be_a_unit_dual_quaternion(pose: tuple[float, ...], complaint: str) -> None:
    with pytest.raises(ValidationError, match=complaint):
        Goal(header=HEADER, task="pose", pose=pose)
    with pytest.raises(ValidationError, match=complaint):
        RobotState.model_validate(STATE.model_dump() | {"end_effector": pose})


def test_unit_tolerance_is_one_in_a_million() -> None:
    nearly = (1.0 + 5e-7, *IDENTITY_POSE[1:])
    assert Goal(header=HEADER, task="pose", pose=nearly).pose == nearly
    with pytest.raises(ValidationError, match="norm"):
        Goal(header=HEADER, task="pose", pose=(1.0 + 2e-6, *IDENTITY_POSE[1:]))


@pytest.mark.parametrize(
    ("fields", "complaint"),
    [
        ({"task": "pose"}, "a pose task needs a pose"),
        ({"task": "pose", "pose": QUARTER_TURN_SHIFTED, "position": (0, 0, 0)}, "no position"),
        ({"task": "position"}, "a position task needs a position"),
        ({"task": "position", "position": (0, 0, 0), "pose": IDENTITY_POSE}, "no pose"),
        ({"task": "orientation", "pose": IDENTITY_POSE}, "task"),
        ({"task": "point", "point": (0, 0), "lookahead": 0.1}, "a point task needs an arm"),
        ({"task": "heading", "heading": 1.0, "arm": (0, 0, 0, 0, 0)}, "needs a point"),
        (
            {
                "task": "point",
                "point": (0, 0),
                "arm": (0, 0, 0, 0, 0),
                "lookahead": 0.1,
                "heading": 0.0,
            },
            "a point task takes no heading",
        ),
        (
            {"task": "point", "point": (0, math.nan), "arm": (0, 0, 0, 0, 0), "lookahead": 0.1},
            "point",
        ),
        ({"task": "pose", "pose": IDENTITY_POSE, "eta": 0.0}, "eta"),
        ({"task": "pose", "pose": IDENTITY_POSE, "beta": -1.0}, "beta"),
    ],
)
def test_goal_target_must_match_task(fields: dict[str, Any], complaint: str) -> None:
    with pytest.raises(ValidationError, match=complaint):
        Goal(header=HEADER, **fields)


def test_goal_gains_default_to_the_controllers_own() -> None:
    goal = Goal(header=HEADER, task="position", position=(1.0, 2.0, 0.5))
    assert (goal.eta, goal.beta, goal.pose) == (None, None, None)
    assert POSE_GOAL.eta == 5.0


@pytest.mark.parametrize(("encoding", "pixel_bytes"), [("mono8", 1), ("bgr8", 3), ("rgb8", 3)])
def test_image_data_must_fill_width_height_channels(encoding: str, pixel_bytes: int) -> None:
    fields = {**IMAGE.model_dump(), "encoding": encoding, "width": 4, "height": 3}
    frame = CameraFrame.model_validate(fields | {"data": bytes(12 * pixel_bytes)})
    assert len(frame.data) == 12 * pixel_bytes
    with pytest.raises(ValidationError, match=f"data has 13 bytes, expected {12 * pixel_bytes}"):
        CameraFrame.model_validate(fields | {"data": bytes(13)})


def test_image_repr_leaves_out_the_pixels() -> None:
    assert len(repr(IMAGE)) < 500


def test_joint_states_must_line_up() -> None:
    with pytest.raises(ValidationError, match=r"lengths \(2, 2, 1\)"):
        JointStates(header=HEADER, names=("a", "b"), positions=(0, 0), velocities=(0,))
    with pytest.raises(ValidationError, match="not unique"):
        JointStates(header=HEADER, names=("a", "a"), positions=(0, 0), velocities=(0, 0))


def test_obstacle_radius_is_positive() -> None:
    with pytest.raises(ValidationError, match="radius"):
        Circle(x=0.0, y=0.0, radius=0.0)


def test_a_plane_must_be_a_solid_wbc_accepts() -> None:
    """A unit normal, and a footprint only on a horizontal plane, convex: the error names the
    field, as wbc.geometry.obstacles3d does."""
    with pytest.raises(ValidationError, match="normal: expected a unit vector"):
        Plane(normal=(0.0, 0.0, 2.0), offset=0.4)
    with pytest.raises(ValidationError, match="footprint: only a horizontal plane"):
        Plane(normal=(1.0, 0.0, 0.0), offset=0.4, footprint=((0, 0), (1, 0), (1, 1)))
    with pytest.raises(ValidationError, match="radius"):
        Cylinder(x=0.0, y=0.0, radius=-0.1)
    with pytest.raises(ValidationError, match="radius"):
        Cylinder(x=0.0, y=0.0, radius=1e300)


def test_solids_come_back_as_the_wbc_obstacles_they_were_made_of() -> None:
    solids = (
        obstacles3d.Plane((0.0, 0.0, 1.0), 0.4, ((0.5, -0.4), (1.1, -0.4), (1.1, 0.4))),
        obstacles3d.Cylinder(0.2, -0.3, 0.05, None, "pole"),
    )
    assert Solids.of(solids).solids() == solids
