"""view.client_goals: what a Foxglove client publishes on goal/request becomes the goal the
state estimator would measure at that place (eq. 6.3), or is refused saying why."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from messages.header import Header
from view.client_goals import GoalRefused, client_goal, marker_pose
from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.geometry.scenarios import HOME
from wbc.planar import offset_pose, planar_pose

HEADER = Header(stamp_ns=5_000_000_000, frame="world", seq=0, source="view")
OFFSET = offset_pose(0.0, 0.0, 0.471698, 0.0, -0.484884, 0.167468)
"""x_d^2 of deploy/sim.yaml: the gripper over the bin."""


def pose_in_frame(x: float, y: float, yaw: float, frame: str = "world", **pose: object) -> bytes:
    orientation = {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}
    fields = {"position": {"x": x, "y": y, "z": 0.0}, "orientation": orientation, **pose}
    return json.dumps(
        {"timestamp": {"sec": 1, "nsec": 0}, "frame_id": frame, "pose": fields}
    ).encode()


def test_a_published_pose_is_the_goal_of_a_bin_standing_there() -> None:
    goal = client_goal("foxglove.PoseInFrame", pose_in_frame(0.6, -0.2, 0.4), OFFSET, HEADER, HOME)
    assert goal.task == "pose" and goal.header == HEADER
    expected = dq.mul(planar_pose(0.6, -0.2, 0.4), OFFSET)
    assert np.allclose(goal.pose, expected, atol=1e-12)


@pytest.mark.parametrize("schema", ["foxglove.Pose", "geometry_msgs/PoseStamped"])
def test_a_pose_alone_and_a_stamped_pose_give_the_same_goal(schema: str) -> None:
    fields = json.loads(pose_in_frame(0.6, -0.2, 0.4))
    data = (
        fields["pose"]
        if schema == "foxglove.Pose"
        else {
            "header": {"frame_id": "world", "stamp": {"sec": 1, "nsec": 0}},
            "pose": fields["pose"],
        }
    )
    goal = client_goal(schema, json.dumps(data).encode(), OFFSET, HEADER, HOME)
    assert np.allclose(goal.pose, dq.mul(planar_pose(0.6, -0.2, 0.4), OFFSET), atol=1e-12)


@pytest.mark.parametrize(
    ("schema", "data", "reason"),
    [
        ("foxglove.PoseInFrame", b"{", "not JSON"),
        ("foxglove.PoseInFrame", b"[1, 2]", "expected a foxglove.PoseInFrame object"),
        (
            "foxglove.Point3",
            pose_in_frame(0.6, -0.2, 0.4),
            "goal/request takes foxglove.PoseInFrame",
        ),
        (
            "foxglove.PoseInFrame",
            pose_in_frame(0.6, -0.2, 0.4, frame="camera"),
            "frame_id 'camera': a goal is given in 'world'",
        ),
        (
            "foxglove.PoseInFrame",
            pose_in_frame(math.nan, -0.2, 0.4),
            "position.x: expected a finite number, got nan",
        ),
        (
            "foxglove.PoseInFrame",
            pose_in_frame(0.6, -0.2, 0.4, position={"x": "far"}),
            "position.x: expected a number, got 'far'",
        ),
        (
            "foxglove.PoseInFrame",
            pose_in_frame(0.6, -0.2, 0.4, orientation={"w": 0.5}),
            "orientation has norm 0.5, expected 1",
        ),
        (
            "foxglove.PoseInFrame",
            pose_in_frame(0.6, -0.2, 0.4, orientation={"w": 2.0}),
            (
                "pose.orientation.w = 2.0 is out of range: "
                "a unit quaternion's components lie in [-1, 1]"
            ),
        ),
        (
            "foxglove.PoseInFrame",
            pose_in_frame(12.0, 0.0, 0.0),
            "farther than the 10 m a plan may cover",
        ),
        (
            "foxglove.PoseInFrame",
            pose_in_frame(1.0, 1.0, 0.0),
            "lies inside obstacle 1 at (1.00, 1.00)",
        ),
    ],
)
def test_a_goal_that_cannot_be_is_refused_saying_why(schema: str, data: bytes, reason: str) -> None:
    with pytest.raises(GoalRefused) as refused:
        client_goal(schema, data, OFFSET, HEADER, HOME, (Circle(1.0, 1.0, 0.2),))
    assert reason in str(refused.value)


def test_a_goal_below_the_floor_is_refused() -> None:
    under = offset_pose(0.0, 0.0, -0.1, 0.0, 0.0, 0.0)
    with pytest.raises(GoalRefused, match="0.100 m below the floor"):
        client_goal("foxglove.PoseInFrame", pose_in_frame(0.6, 0.0, 0.0), under, HEADER, HOME)


def test_before_the_robot_is_known_only_the_message_is_checked() -> None:
    far = pose_in_frame(12.0, 0.0, 0.0)
    goal = client_goal("foxglove.PoseInFrame", far, OFFSET, HEADER, None)
    assert np.allclose(dq.translation(np.array(goal.pose))[1:3], [12.0, 0.0])
    assert np.allclose(marker_pose("foxglove.PoseInFrame", far), planar_pose(12.0, 0.0, 0.0))


def raw_pose(position: object, frame: object = "world") -> bytes:
    """A PoseInFrame whose position is ``position`` as given (JSON text or a value)."""
    text = position if isinstance(position, str) else json.dumps(position)
    return (
        f'{{"frame_id": {json.dumps(frame)}, "pose": {{"position": {text}, '
        '"orientation": {"w": 1.0}}}'
    ).encode()


@pytest.mark.parametrize(
    ("data", "reason"),
    [
        (
            raw_pose('{"x": 1' + "0" * 400 + "}"),
            "pose.position.x = an integer of 401 digits is out of range: a goal lies within "
            "1000 m of F0",
        ),
        (raw_pose("[" * 5000 + "]" * 5000), "not a goal: its JSON is nested too deeply"),
        (
            raw_pose({"x": 1e154, "y": 1e154, "z": 0.0}),
            "pose.position.x = 1e+154 is out of range: a goal lies within 1000 m of F0",
        ),
        (raw_pose({"x": 0.5, "y": -1e300}), "pose.position.y = -1e+300 is out of range"),
        (
            b'{"frame_id": "world", "pose": {"orientation": {"w": 1.0}}}',
            "pose.position is missing: a goal needs it",
        ),
        (b'{"frame_id": "world"}', "pose is missing: a goal needs it"),
        (raw_pose([1, 2]), "pose.position: expected an object, got a list of 2 entries"),
        (raw_pose({"x": "x" * 5000}), "pose.position.x: expected a number, got 'xxxx"),
        (raw_pose({"x": 0.5}, frame="c" * 5000), "frame_id 'cccc"),
        (raw_pose({"x": 0.5}, frame="c" * 20_000), "a message of 20"),
    ],
)
def test_a_hostile_goal_is_refused_in_a_few_words(data: bytes, reason: str) -> None:
    """Magnitudes are checked before anything is computed from them, and nothing the client
    sent comes back longer than a few words (a refusal goes to every client)."""
    for q_now in (HOME, None):
        with pytest.raises(GoalRefused) as refused:
            client_goal("foxglove.PoseInFrame", data, OFFSET, HEADER, q_now)
        assert reason in str(refused.value)
        assert len(str(refused.value)) < 150, str(refused.value)
