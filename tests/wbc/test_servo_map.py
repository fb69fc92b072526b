"""The arm's servos as the robot description places them (wbc.servo_map; ``servos:``: ids,
offsets and directions per joint): read, mapped both ways, and refused naming the field."""

from __future__ import annotations

from pathlib import Path

import pytest

from profiles.deploy_files import ROBOT_FILE, ROBOTS_DIR
from tests.wbc.mapped_servos import mapped_robot
from wbc.robot import RobotDescriptionError
from wbc.servo_map import ServoMap


def test_little_johns_servos_are_1_to_5_from_the_centre_each_its_joints_way() -> None:
    assert ServoMap.of(ROBOT_FILE, 5) == ServoMap((1, 2, 3, 4, 5), (0.0,) * 5, (1,) * 5)


def test_a_description_without_servos_has_them_plain() -> None:
    assert ServoMap.of(ROBOTS_DIR / "snake12.yaml", 12) == ServoMap.plain(12)


def test_a_joint_maps_to_its_servo_and_back(tmp_path: Path) -> None:
    servos = ServoMap.of(mapped_robot(tmp_path), 5)
    assert servos.servo_angle(1, 0.5) == -0.5 and servos.servo_angle(4, 0.5) == -0.2
    for joint in range(5):
        assert servos.joint_position(joint, servos.servo_angle(joint, 0.7)) == pytest.approx(0.7)


@pytest.mark.parametrize(
    ("servos", "complaint"),
    [
        ("servos: [1, 2]\n", "servos: expected a mapping"),
        ("servos: {ids: [1, 2, 3]}\n", r"servos.ids: expected 5 values, one per joint"),
        ("servos: {ids: [1, 1, 2, 3, 4]}\n", "servos.ids: expected distinct ids in 0..253"),
        ("servos: {ids: [1, 2, 3, 4, 254]}\n", "servos.ids: expected distinct ids in 0..253"),
        ("servos: {offsets: [0, 0, 0, 0, .nan]}\n", "servos.offsets: expected finite angles"),
        ("servos: {directions: [1, 1, 0, 1, 1]}\n", r"servos.directions: expected \+1 or -1"),
        ("servos: {gears: [1, 1, 1, 1, 1]}\n", r"servos: unknown fields \['gears'\]"),
    ],
)
def test_a_servo_section_that_cannot_be_used_is_refused_naming_the_field(
    tmp_path: Path, servos: str, complaint: str
) -> None:
    with pytest.raises(RobotDescriptionError, match=complaint):
        ServoMap.of(mapped_robot(tmp_path, servos), 5)
