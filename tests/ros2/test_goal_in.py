"""A goal from ROS 2 (a PoseStamped's CDR) turned into the pose goal in the world, through
the frame it names; and each refusal, with the kind the bridge counts it under."""

from __future__ import annotations

import math

import numpy as np
import pytest

from messages.header import Header
from ros2.goal_in import ECHO_CHARS, MAX_BYTES, Refused, goal_of
from tests.ros2.pose_stamped import pose_stamped
from wbc import dq

HEADER = Header(stamp_ns=1, frame="world", seq=0, source="test")
BASE = np.array([[0.0, -1.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0, 0, 0, 1]])
"""A base a quarter turn about z, at (1, 0, 0) in the world."""
FRAMES = {"world": np.eye(4), "base_footprint": BASE}


def refusal(data: bytes, frames=FRAMES) -> Refused:
    with pytest.raises(Refused) as caught:
        goal_of(data, frames, HEADER)
    return caught.value


def test_a_goal_in_the_world_is_the_pose_it_gives() -> None:
    half = math.pi / 8  # a quarter turn about x
    goal = goal_of(
        pose_stamped("world", (0.5, -0.2, 0.4), (math.cos(half), math.sin(half), 0, 0)),
        FRAMES,
        HEADER,
    )
    pose = np.array(goal.pose)
    assert goal.task == "pose" and goal.header == HEADER
    assert dq.translation(pose)[1:] == pytest.approx([0.5, -0.2, 0.4])
    assert abs(np.dot(pose[:4], [math.cos(half), math.sin(half), 0, 0])) == pytest.approx(1.0)


def test_a_goal_in_the_bases_frame_is_carried_into_the_world() -> None:
    goal = goal_of(pose_stamped("base_footprint", (0.5, 0.0, 0.4)), FRAMES, HEADER)
    pose = np.array(goal.pose)
    # 0.5 m ahead of a base facing +y at (1, 0): (1, 0.5), turned a quarter about z
    assert dq.translation(pose)[1:] == pytest.approx([1.0, 0.5, 0.4])
    quarter = [math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)]
    assert abs(np.dot(pose[:4], quarter)) == pytest.approx(1.0)


def test_bytes_that_are_no_pose_stamped_or_too_many_are_malformed_cdr() -> None:
    assert refusal(b"\x00\x01\x00\x00\xff").kind == "malformed_cdr"
    good = pose_stamped("world", (1.0, 0.0, 0.5))
    too_many = refusal(good + bytes(MAX_BYTES + 1 - len(good)))
    assert too_many.kind == "malformed_cdr" and f"{MAX_BYTES + 1} bytes" in str(too_many)


def test_a_frame_not_in_the_tree_is_refused_naming_the_tree_and_echoing_little() -> None:
    refused = refusal(pose_stamped("nowhere", (1.0, 0.0, 0.5)))
    assert refused.kind == "frame"
    assert "'nowhere'" in str(refused) and "world, base_footprint" in str(refused)
    long_name = "x" * 500
    said = str(refusal(pose_stamped(long_name, (1.0, 0.0, 0.5))))
    assert "x" * ECHO_CHARS + "..." in said and "x" * (ECHO_CHARS + 1) not in said
    assert refusal(pose_stamped("base_footprint", (1, 0, 0.5)), {"world": np.eye(4)}).kind == (
        "frame"
    )  # without a state only the world is a frame


@pytest.mark.parametrize(
    ("position", "orientation", "said"),
    [
        ((math.nan, 0.0, 0.5), (1.0, 0, 0, 0), "not finite"),
        ((1.0, math.inf, 0.5), (1.0, 0, 0, 0), "not finite"),
        ((1.0, 0.0, 0.5), (1.0, 0, 0, math.nan), "not finite"),
        ((1.0, 0.0, 0.5), (2.0, 0, 0, 0), "norm 2, expected 1"),
        ((1.0, 0.0, 0.5), (0.0, 0, 0, 0), "norm 0, expected 1"),
        ((1.0, 0.0, -0.25), (1.0, 0, 0, 0), "0.250 m below the floor"),
    ],
)
def test_a_pose_that_is_none_is_a_refused_goal(position, orientation, said: str) -> None:
    refused = refusal(pose_stamped("world", position, orientation))
    assert refused.kind == "goal" and said in str(refused)


def test_a_goal_not_finite_once_in_the_world_is_refused() -> None:
    far = BASE.copy()
    far[0, 3] = 1e308
    refused = refusal(pose_stamped("base_footprint", (0.0, -1e308, 0.5)), {"base_footprint": far})
    assert refused.kind == "goal" and "not finite in the world" in str(refused)
