"""messages.base: what every message model refuses (a float that is not finite, a change, an
unknown field), the pose every model takes (a unit dual quaternion), and the arm's joints and
their names (``RobotState``'s and ``ArmCommand``'s, which both take base's rules)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import given
from pydantic import ValidationError

from messages import (
    IDENTITY_POSE,
    MESSAGE_TYPES,
    ArmCommand,
    Circle,
    Goal,
    MarkerDetection,
    RobotState,
)
from messages.base import Message
from tests.messages.message_examples import EXAMPLES, HEADER, STATE
from tests.messages.message_strategies import unit_dual_quaternions


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
