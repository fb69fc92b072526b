"""The robot's parts that 3-D obstacles must clear (wbc.collision_model): a description's
``collision`` section read, or refused naming the field; a point placed by its frame and
offset; a segment whose ends leave its frame's axis refused."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from profiles.deploy_files import ROBOT_FILE
from wbc import dq
from wbc.collision_model import axis_direction, check_segments, collision_model, point_positions
from wbc.robot import MobileManipulator

LITTLE_JOHN = yaml.safe_load(ROBOT_FILE.read_text())["collision"]


def test_little_johns_parts_are_read_points_first() -> None:
    model = collision_model(LITTLE_JOHN, frames=6)
    assert model.names == ("base", "elbow", "wrist", "gripper", "forearm", "hand")
    forearm = model.segments[0]
    assert (forearm.frame, forearm.axis, forearm.start, forearm.end) == (3, "z", 1, 2)
    assert collision_model(None, frames=6).names == ()


def test_a_point_is_its_frame_moved_by_its_offset() -> None:
    """A frame at (1, 2, 3) turned 90 degrees about z: an offset (0.5, 0, 0) in it lies at
    (1, 2.5, 3); its x axis points along the world's y."""
    model = collision_model({"points": [{"frame": 0, "offset": [0.5, 0, 0], "radius": 0.1}]}, 1)
    frame = dq.pose(dq.rotation_quaternion(math.pi / 2, [0, 0, 1]), [1.0, 2.0, 3.0])
    np.testing.assert_allclose(point_positions([frame], model), [[1.0, 2.5, 3.0]], atol=1e-12)
    np.testing.assert_allclose(axis_direction(frame, "x"), [0.0, 1.0, 0.0], atol=1e-12)
    assert model.names == ("collision.points[0]",)  # unnamed: named by its field


POINT = {"name": "p", "frame": 0, "radius": 0.1}


@pytest.mark.parametrize(
    ("section", "complaint"),
    [
        ([], "collision: expected a mapping of `points` and `segments`"),
        ({"points": [POINT], "spheres": []}, "expected a mapping of `points` and `segments`"),
        ({"points": {"p": POINT}}, r"collision.points: expected a list of mappings"),
        ({"points": [{**POINT, "frame": 6}]}, r"points\[0\].frame: expected a frame index 0 to 5"),
        ({"points": [{**POINT, "radius": 0}]}, r"points\[0\].radius: expected a number > 0"),
        ({"points": [{**POINT, "offset": [0, 0]}]}, r"points\[0\].offset: expected 3 numbers"),
        ({"points": [{**POINT, "colour": 1}]}, r"points\[0\]: unknown fields \['colour'\]"),
        ({"points": [POINT, POINT]}, "collision.points: names must differ"),
        (
            {"points": [POINT], "segments": [{"frame": 0, "axis": "w"}]},
            r"segments\[0\].axis: expected one of x, y, z",
        ),
        (
            {"points": [POINT], "segments": [{"frame": 0, "axis": "z", "start": "p", "end": "q"}]},
            r"segments\[0\].end: expected the name of a point \(p\)",
        ),
        (
            {"points": [POINT], "segments": [{"frame": 0, "axis": "z", "start": "p", "end": "p"}]},
            "start and end must be two different points",
        ),
    ],
)
def test_a_section_that_cannot_be_used_is_refused_naming_the_field(
    section: object, complaint: str
) -> None:
    with pytest.raises(ValueError, match=complaint):
        collision_model(section, frames=6)


def test_a_segment_whose_ends_leave_its_axis_is_refused() -> None:
    """Little John's forearm lies along frame 3's z axis; along its x axis, it does not."""
    robot = MobileManipulator.from_yaml(ROBOT_FILE)
    check_segments(robot, robot.collision)
    askew = {**LITTLE_JOHN, "segments": [{**LITTLE_JOHN["segments"][0], "axis": "x"}]}
    with pytest.raises(ValueError, match=r"segments\[0\] \(forearm\): point (elbow|wrist) is "):
        check_segments(robot, collision_model(askew, frames=6))
