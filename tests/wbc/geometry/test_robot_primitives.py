"""Where the robot's collision parts are and their Jacobians (wbc/geometry/robot_primitives.py):
central finite differences over random configurations, and DQ Robotics' line Jacobian."""

from __future__ import annotations

import numpy as np
from dqrobotics import DQ
from dqrobotics.robot_modeling import DQ_Kinematics

from profiles.deploy_files import ROBOT_FILE
from tests.wbc.wbc_scenarios import central_difference, configurations
from wbc import dq
from wbc.geometry.plucker import is_line, line
from wbc.geometry.robot_primitives import (
    line_jacobians,
    primitive_kinematics,
    translation_jacobians,
    translations,
)
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
FD_TOL = 1e-7
ORACLE_TOL = 1e-12


def test_part_jacobians_are_the_derivatives_of_the_parts() -> None:
    for q in configurations(ROBOT, 10, seed=12):
        parts = primitive_kinematics(ROBOT, q)
        points = central_difference(lambda c: primitive_kinematics(ROBOT, c).points, q)
        lines = central_difference(lambda c: primitive_kinematics(ROBOT, c).lines, q)
        np.testing.assert_allclose(parts.point_jacobians, points, atol=FD_TOL)
        np.testing.assert_allclose(parts.line_jacobians, lines, atol=FD_TOL)
        assert all(is_line(x) for x in parts.lines)


def line_of(
    pose: np.ndarray, jacobian: np.ndarray, axis: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The line along ``axis`` through one frame and its Jacobian, by the stack version."""
    stack = pose[None], jacobian[None]
    lines, jacobians = line_jacobians(
        *stack, axis[None], translations(stack[0]), translation_jacobians(*stack)
    )
    return lines[0], jacobians[0]


def test_line_jacobian_matches_dqrobotics() -> None:
    for q in configurations(ROBOT, 50, seed=13):
        poses, jacobians = ROBOT.frame_kinematics(q)
        for frame in range(6):
            for axis in (dq.I_, dq.J_, dq.K_):
                expected = DQ_Kinematics.line_jacobian(jacobians[frame], DQ(poses[frame]), DQ(axis))
                found, jacobian = line_of(poses[frame], jacobians[frame], axis)
                np.testing.assert_allclose(jacobian, expected, atol=ORACLE_TOL)
                direction = dq.qmul(dq.qmul(poses[frame][:4], axis), dq.qconj(poses[frame][:4]))
                np.testing.assert_allclose(
                    found, line(direction, dq.translation(poses[frame])), atol=1e-12
                )


def test_segments_run_along_their_lines_from_end_to_end() -> None:
    """The forearm is the elbow-wrist segment on z of frame 3, the hand the wrist-gripper one
    on x of frame 5; their ends' parameters along the line are 0.1225 and 0.17 m apart."""
    for q in configurations(ROBOT, 10, seed=14):
        parts = primitive_kinematics(ROBOT, q)
        for i, segment in enumerate(ROBOT.collision.segments):
            start, end = parts.points[segment.start, 1:], parts.points[segment.end, 1:]
            foot = np.cross(parts.lines[i, 1:4], parts.lines[i, 5:8])
            for s, point in zip(parts.ends[i], (start, end), strict=True):
                np.testing.assert_allclose(foot + s * parts.lines[i, 1:4], point, atol=1e-12)
        np.testing.assert_allclose(
            np.abs(np.diff(parts.ends, axis=1)).ravel(), [0.1225, 0.17], atol=1e-12
        )


def test_line_of_a_pose_passes_through_its_origin_along_its_axis() -> None:
    pose = dq.pose(dq.rotation_quaternion(np.pi / 2, [0, 1, 0]), [1.0, 2.0, 3.0])
    z_axis, _ = line_of(pose, np.zeros((8, 8)), dq.K_)
    np.testing.assert_allclose(z_axis, line([1, 0, 0], [1, 2, 3]), atol=1e-12)
