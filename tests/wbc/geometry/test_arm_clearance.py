"""How far each collision part is from each solid, and the penetrations as they begin
(wbc/geometry/arm_clearance.py)."""

from __future__ import annotations

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE
from wbc.collision_model import point_positions
from wbc.geometry.arm_clearance import PenetrationCount, part_clearances
from wbc.geometry.obstacles3d import Plane
from wbc.geometry.scenarios import HOME
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)


def test_a_points_clearance_from_a_wall_is_its_distance_less_its_radius() -> None:
    wall = Plane((-1.0, 0.0, 0.0), -2.0)  # the solid is x > 2
    clearances = part_clearances(ROBOT, HOME, [wall])
    model = ROBOT.collision
    assert clearances.shape == (len(model.names), 1)
    centres = point_positions(ROBOT.frames(HOME), model)
    for i, point in enumerate(model.points):
        assert clearances[i, 0] == pytest.approx(2.0 - centres[i][0] - point.radius)
    moved = HOME + np.array([1.0, 0, 0, 0, 0, 0, 0, 0])  # the robot 1 m nearer: all 1 m less
    np.testing.assert_allclose(part_clearances(ROBOT, moved, [wall]), clearances - 1.0)


def test_a_penetration_is_counted_once_as_it_begins() -> None:
    count = PenetrationCount()
    for step in ([[0.1, 0.2]], [[-0.1, 0.2]], [[-0.2, 0.2]], [[0.1, -0.1]], [[-0.1, -0.1]]):
        count.update(np.array(step))
    assert count.count == 3 and count.penetrating
    count.update(np.array([[0.1, 0.1]]))
    assert not count.penetrating
