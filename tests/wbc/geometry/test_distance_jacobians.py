"""The distance Jacobians of the arm's parts (wbc/geometry/distance_jacobians.py,
and the frames' Jacobians they start from): central finite differences over random
configurations, and DQ Robotics' DQ_Kinematics and DQ_Geometry, which have the same ones."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pytest
from dqrobotics import DQ
from dqrobotics.robot_modeling import DQ_Kinematics
from dqrobotics.utils import DQ_Geometry

from profiles.deploy_files import ROBOT_FILE
from tests.wbc.wbc_scenarios import central_difference, configurations, oracle_chain
from wbc.geometry.distance_jacobians import (
    ParallelLinesError,
    line_to_line_distance_jacobian,
    line_to_line_squared_distance,
    point_to_line_distance_jacobian,
    point_to_line_squared_distance,
    point_to_plane_distance,
    point_to_plane_distance_jacobian,
    point_to_point_distance_jacobian,
    point_to_point_squared_distance,
)
from wbc.geometry.plucker import line, plane
from wbc.geometry.robot_primitives import (
    primitive_kinematics,
)
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
FD_TOL = 1e-7
ORACLE_TOL = 1e-12
NAMES = ROBOT.collision.names
POINTS = len(ROBOT.collision.points)


def workspace(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A random plane (unit normal, offset) and a random line, both vec8."""
    rng = np.random.default_rng(seed)
    normal = rng.normal(size=3)
    return (
        plane(normal / np.linalg.norm(normal), rng.uniform(-1.0, 1.0)),
        line(rng.normal(size=3), rng.uniform(-1.0, 1.0, 3)),
    )


# --- Frames and parts -------------------------------------------------------------------------


@pytest.mark.parametrize("frame", range(1, 6))
def test_frame_poses_and_jacobians_match_dqrobotics_chains(frame: int) -> None:
    body = oracle_chain(ROBOT, frame)
    for q in configurations(ROBOT, 30, seed=frame):
        poses, jacobians = ROBOT.frame_kinematics(q)
        moving = 3 + frame
        np.testing.assert_allclose(poses[frame], body.fkm(q[:moving]).vec8(), atol=ORACLE_TOL)
        np.testing.assert_allclose(
            jacobians[frame, :, :moving], body.pose_jacobian(q[:moving]), atol=ORACLE_TOL
        )
        np.testing.assert_array_equal(jacobians[frame, :, moving:], 0.0)


def test_frame_jacobians_are_the_derivatives_of_the_frames() -> None:
    for q in configurations(ROBOT, 10, seed=11):
        _, jacobians = ROBOT.frame_kinematics(q)
        expected = central_difference(lambda c: ROBOT.frame_kinematics(c)[0], q)
        np.testing.assert_allclose(jacobians, expected, atol=FD_TOL)


# --- Distances and their Jacobians ------------------------------------------------------------


def corner(seed: int) -> np.ndarray:
    """A random point of the workspace, vec4."""
    return np.r_[0.0, np.random.default_rng(seed).uniform(-1.0, 1.0, 3)]


@dataclass(frozen=True)
class PointDistance:
    """A distance from a robot's point to a workspace primitive, its Jacobian (ours, from the
    point's Jacobian, the point and the primitive) and DQ Robotics' of both."""

    seed: int
    primitive: Callable[[int], np.ndarray]
    distance: Callable[[np.ndarray, np.ndarray], float]
    jacobian: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    oracle_jacobian: Callable[..., np.ndarray]
    oracle_distance: Callable[..., float]


POINT_DISTANCES = {
    "plane": PointDistance(
        20,
        lambda i: workspace(i)[0],
        point_to_plane_distance,
        lambda jacobian, _, w: point_to_plane_distance_jacobian(jacobian, w),
        DQ_Kinematics.point_to_plane_distance_jacobian,
        DQ_Geometry.point_to_plane_distance,
    ),
    "line": PointDistance(
        30,
        lambda i: workspace(i)[1],
        point_to_line_squared_distance,
        point_to_line_distance_jacobian,
        DQ_Kinematics.point_to_line_distance_jacobian,
        DQ_Geometry.point_to_line_squared_distance,
    ),
    "point": PointDistance(
        50,
        corner,
        point_to_point_squared_distance,
        point_to_point_distance_jacobian,
        DQ_Kinematics.point_to_point_distance_jacobian,
        DQ_Geometry.point_to_point_squared_distance,
    ),
}


@pytest.mark.parametrize("part", range(POINTS))
@pytest.mark.parametrize("kind", POINT_DISTANCES)
def test_point_distance_jacobians_are_the_derivatives_and_dqrobotics(kind: str, part: int) -> None:
    d = POINT_DISTANCES[kind]
    for index, q in enumerate(configurations(ROBOT, 20, seed=d.seed + part)):
        primitive = d.primitive(index)
        parts = primitive_kinematics(ROBOT, q)
        point, jacobian = parts.points[part], parts.point_jacobians[part]
        row = d.jacobian(jacobian, point, primitive)
        np.testing.assert_allclose(
            row,
            central_difference(
                lambda c, w=primitive: d.distance(primitive_kinematics(ROBOT, c).points[part], w), q
            ),
            atol=FD_TOL,
        )
        oracle = d.oracle_jacobian(jacobian, DQ(point), DQ(primitive))
        np.testing.assert_allclose(row, oracle.ravel(), atol=ORACLE_TOL)
        assert d.distance(point, primitive) == pytest.approx(
            d.oracle_distance(DQ(point), DQ(primitive)), abs=1e-12
        )


@pytest.mark.parametrize("segment", range(len(ROBOT.collision.segments)))
def test_line_to_line_jacobian_is_the_derivative_and_dqrobotics(segment: int) -> None:
    for index, q in enumerate(configurations(ROBOT, 20, seed=40 + segment)):
        _, workspace_line = workspace(100 + index)
        parts = primitive_kinematics(ROBOT, q)
        robot_line, jacobian = parts.lines[segment], parts.line_jacobians[segment]
        row = line_to_line_distance_jacobian(jacobian, robot_line, workspace_line)
        expected = central_difference(
            lambda c, w=workspace_line: line_to_line_squared_distance(
                primitive_kinematics(ROBOT, c).lines[segment], w
            ),
            q,
        )
        np.testing.assert_allclose(row, expected, atol=1e-6 * max(1.0, np.abs(row).max()))
        oracle = DQ_Kinematics.line_to_line_distance_jacobian(
            jacobian, DQ(robot_line), DQ(workspace_line)
        )
        np.testing.assert_allclose(row, oracle.ravel(), atol=1e-10 * max(1.0, np.abs(row).max()))
        assert line_to_line_squared_distance(robot_line, workspace_line) == pytest.approx(
            DQ_Geometry.line_to_line_squared_distance(DQ(robot_line), DQ(workspace_line)),
            rel=1e-10,
            abs=1e-12,
        )


def test_distances_are_the_euclidean_ones() -> None:
    """The table top z = 0.3 from (1, 2, 0.5) is 0.2; a vertical pole through (1, 0) is 2 from
    (1, 2, z), squared 4; the x axis raised to z = 0.5 is 0.5 from the pole, squared 0.25."""
    point = np.array([0.0, 1.0, 2.0, 0.5])
    assert point_to_plane_distance(point, plane([0, 0, 1], 0.3)) == pytest.approx(0.2)
    pole = line([0, 0, 1], [1, 0, 0])
    assert point_to_line_squared_distance(point, pole) == pytest.approx(4.0)
    assert line_to_line_squared_distance(line([1, 0, 0], [0, 0, 0.5]), pole) == pytest.approx(0.0)
    raised = line([0, 1, 0], [3.0, 0, 0.5])
    assert line_to_line_squared_distance(raised, pole) == pytest.approx(4.0)
    beside = line([0, 0, 1], [1.0, 0.5, 0])
    assert line_to_line_squared_distance(beside, pole) == pytest.approx(0.25)  # parallel


def test_parallel_lines_have_no_distance_jacobian() -> None:
    pole = line([0, 0, 1], [1, 0, 0])
    with pytest.raises(ParallelLinesError, match="parallel"):
        line_to_line_distance_jacobian(np.ones((8, 8)), line([0, 0, -1], [2, 0, 0]), pole)
