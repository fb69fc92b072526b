"""A distance's row from the twists of the forward pass (wbc/geometry/wrench_rows.py) equals its
weights times the part's Jacobian: J_t of 4.18 and DQ Robotics' line Jacobian
(wbc/geometry/robot_primitives.py), and DQ Robotics' own translation and line Jacobians on truncated
DQ_WholeBody chains; a point with an offset in its frame included. The shared forward pass gives the
task what ``kinematics`` gives."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from dqrobotics import DQ
from dqrobotics.robot_modeling import DQ_Kinematics

from profiles.deploy_files import ROBOT_FILE
from tests.wbc.wbc_scenarios import configurations, oracle_chain
from wbc import dq
from wbc.collision_model import AXES, CollisionModel, CollisionPoint
from wbc.geometry.robot_primitives import primitive_kinematics
from wbc.geometry.wrench_rows import line_wrench, point_wrench, wrench_rows
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
ORACLE_TOL = 1e-12


def with_offsets(robot: MobileManipulator) -> MobileManipulator:
    """The same robot with two more points, off their frames' origins."""
    points = (
        *robot.collision.points,
        CollisionPoint("finger", 5, (0.03, 0.012, -0.02), 0.01),
        CollisionPoint("shoulder pad", 1, (-0.02, 0.05, 0.04), 0.02),
    )
    collision = replace(robot.collision, points=points)
    return MobileManipulator(
        np.array(robot.dh),
        robot.base,
        robot.q_min[3:].copy(),
        robot.q_max[3:].copy(),
        robot.velocity_max[3:].copy(),
        robot.name,
        collision,
    )


def test_point_rows_are_the_weights_times_the_translation_jacobian() -> None:
    robot = with_offsets(ROBOT)
    rng = np.random.default_rng(1)
    for q in configurations(ROBOT, 40, seed=2):
        chain = robot.forward(q)
        parts = primitive_kinematics(robot, q, chain)
        weights = rng.normal(size=(len(parts.positions), 3))
        rows = wrench_rows(
            chain,
            [point_wrench(p, w) for p, w in zip(parts.positions, weights, strict=True)],
            parts.point_frames,
        )
        expected = np.einsum("ki,kin->kn", weights, parts.point_jacobians[:, 1:4])
        np.testing.assert_allclose(rows, expected, atol=ORACLE_TOL)


def test_point_positions_with_offsets_are_the_translations_of_their_poses() -> None:
    robot = with_offsets(ROBOT)
    for q in configurations(ROBOT, 20, seed=3):
        parts = primitive_kinematics(robot, q)
        frames = robot.frames(q)
        for point, position in zip(robot.collision.points, parts.positions, strict=True):
            pose = dq.mul(frames[point.frame], dq.pose(dq.ONE[:4], point.offset))
            np.testing.assert_allclose(position, dq.translation(pose)[1:], atol=1e-15)


@pytest.mark.parametrize("frame", range(1, 6))
def test_rows_of_a_frame_match_dqrobotics_jacobians(frame: int) -> None:
    """At frame i's origin and on its axis lines, the wrench rows equal the weights times DQ
    Robotics' translation_jacobian and line_jacobian of the chain up to frame i."""
    body, rng = oracle_chain(ROBOT, frame), np.random.default_rng(frame)
    moving = 3 + frame
    for q in configurations(ROBOT, 20, seed=10 + frame):
        chain = ROBOT.forward(q)
        pose, jacobian = body.fkm(q[:moving]), body.pose_jacobian(q[:moving])
        origin = dq.translation(chain.poses[frame])[1:]
        weights = rng.normal(size=3)
        row = wrench_rows(chain, [point_wrench(origin, weights)], [frame])[0]
        oracle = weights @ DQ_Kinematics.translation_jacobian(jacobian, pose)[1:4]
        np.testing.assert_allclose(row[:moving], oracle, atol=ORACLE_TOL)
        np.testing.assert_array_equal(row[moving:], 0.0)
        for axis in AXES.values():
            line_jacobian = DQ_Kinematics.line_jacobian(jacobian, pose, DQ(axis))
            direction = dq.qmul(
                dq.qmul(chain.poses[frame][:4], axis), dq.qconj(chain.poses[frame][:4])
            )[1:]
            line = np.r_[0.0, direction, 0.0, np.cross(origin, direction)]
            weights8 = rng.normal(size=8) * [0, 1, 1, 1, 0, 1, 1, 1]
            row = wrench_rows(chain, [line_wrench(line, weights8)], [frame])[0]
            np.testing.assert_allclose(row[:moving], weights8 @ line_jacobian, atol=ORACLE_TOL)


def test_segment_rows_are_the_weights_times_the_line_jacobian() -> None:
    rng = np.random.default_rng(4)
    for q in configurations(ROBOT, 40, seed=5):
        chain = ROBOT.forward(q)
        parts = primitive_kinematics(ROBOT, q, chain)
        weights = rng.normal(size=(len(parts.line_list), 8)) * [0, 1, 1, 1, 0, 1, 1, 1]
        rows = wrench_rows(
            chain,
            [line_wrench(x, w) for x, w in zip(parts.line_list, weights, strict=True)],
            parts.segment_frames,
        )
        np.testing.assert_allclose(
            rows, np.einsum("ki,kin->kn", weights, parts.line_jacobians), atol=ORACLE_TOL
        )


def test_the_shared_forward_pass_gives_the_task_what_kinematics_gives() -> None:
    """Bit for bit: runs without solids in 3-D keep their commands."""
    for q in configurations(ROBOT, 20, seed=6):
        chain = ROBOT.forward(q)
        pose, jacobian = ROBOT.kinematics(q)
        assert np.array_equal(chain.pose, pose) and np.array_equal(chain.jacobian, jacobian)
        poses, jacobians = ROBOT.frame_kinematics(q)
        np.testing.assert_allclose(poses[-1], pose, atol=1e-15)
        np.testing.assert_allclose(jacobians[-1], jacobian, atol=1e-15)


def test_a_model_without_parts_has_no_positions() -> None:
    robot = MobileManipulator(
        np.array(ROBOT.dh),
        ROBOT.base,
        ROBOT.q_min[3:].copy(),
        ROBOT.q_max[3:].copy(),
        ROBOT.velocity_max[3:].copy(),
        collision=CollisionModel(),
    )
    parts = primitive_kinematics(robot, configurations(ROBOT, 1, seed=7)[0])
    assert parts.points.shape == (0, 4) and parts.lines.shape == (0, 8)
