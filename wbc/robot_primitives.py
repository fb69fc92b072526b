"""The Jacobians of the robot's collision parts (``wbc.collision_model``) at one configuration.

For a point at ``offset`` in frame i: x = x_i (1 + eps offset / 2), its pose Jacobian
H-(1 + eps offset / 2) J_i and its translation Jacobian J_t (4.18), J_i the pose Jacobian of
frame i (``MobileManipulator.frame_kinematics``: the columns of the joints after frame i are 0).
For a segment on the axis a of frame i: its Plücker line l + eps p x l with l = r a r*
and the line Jacobian of DQ Robotics' ``line_jacobian`` (``line_jacobians``; Marinho et al.
eq. 26-28), and its ends as parameters s along the line, p_0 + s l with p_0 = l x m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wbc import dq
from wbc.collision_model import AXES, offset_pose
from wbc.plucker import foot
from wbc.robot import MobileManipulator, translation_jacobian

Array = np.ndarray

_CONJ4 = np.array([1.0, -1.0, -1.0, -1.0])


@dataclass(frozen=True)
class PrimitiveKinematics:
    """Where the parts are at one configuration, and how they move with q'."""

    points: Array
    """(k, 4) pure quaternions."""
    point_jacobians: Array
    """(k, 4, dof) translation Jacobians."""
    lines: Array
    """(s, 8) Plücker lines of the segments."""
    line_jacobians: Array
    """(s, 8, dof)."""
    ends: Array
    """(s, 2): each segment's ends as p_0 + s l along its line, p_0 = l x m."""


def translations(poses: Array) -> Array:
    """p = 2 D(x) P(x)* (4.12) of each pose of a stack (k, 8): (k, 4)."""
    return 2.0 * (dq.hamiplus4_stack(poses[:, 4:]) @ (poses[:, :4] * _CONJ4)[:, :, None])[:, :, 0]


def translation_jacobians(poses: Array, jacobians: Array) -> Array:
    """J_t = 2 H-_4(P(x*)) J_D + 2 H+_4(D(x)) C4 J_P (4.18) of each pose of a stack: (k, 4, n)."""
    conjugates = poses[:, :4] * _CONJ4
    return 2.0 * (dq.haminus4_stack(conjugates) @ jacobians[:, 4:]
                  + dq.hamiplus4_stack(poses[:, 4:]) @ (jacobians[:, :4] * _CONJ4[:, None]))


_CROSS_INDEX = np.array([[0, 0, 0, 0], [0, 0, 3, 2], [0, 3, 0, 1], [0, 2, 1, 0]])
_CROSS_SIGN = np.array([[0.0, 0, 0, 0], [0, 0, -1, 1], [0, 1, 0, -1], [0, -1, 1, 0]])


def _cross_matrices(vectors: Array) -> Array:
    """C4 (``wbc.plucker.crossmatrix4``) of each pure quaternion of a stack: (k, 4, 4)."""
    return vectors[:, _CROSS_INDEX] * _CROSS_SIGN


def line_jacobians(poses: Array, jacobians: Array, directions: Array, positions: Array,
                   position_jacobians: Array) -> tuple[Array, Array]:  # fmt: skip
    """The lines l + eps p x l through each pose's origin along its local direction d (k, 4),
    and their Jacobians (k, 8, n), DQ Robotics' ``line_jacobian`` of each, given the poses'
    translations p (k, 4) and translation Jacobians J_t (k, 4, n) (4.18):

        l = r d r*,   J_l = (H-_4(d r*) + H+_4(r d) C4) J_r        (J_r the pose rows 1-4)
        m = p x l,    J_m = C4(l)^T J_t + C4(p) J_l
    """
    r, conjugates = poses[:, :4], poses[:, :4] * _CONJ4
    along_r = (dq.hamiplus4_stack(r) @ directions[:, :, None])[:, :, 0]  # r d
    along = (dq.hamiplus4_stack(along_r) @ conjugates[:, :, None])[:, :, 0]  # r d r*
    direction_conj = (dq.hamiplus4_stack(directions) @ conjugates[:, :, None])[:, :, 0]  # d r*
    around_p = _cross_matrices(positions)
    lines = np.concatenate((along, (around_p @ along[:, :, None])[:, :, 0]), axis=1)
    jacobian_l = (dq.haminus4_stack(direction_conj)
                  + dq.hamiplus4_stack(along_r) * _CONJ4) @ jacobians[:, :4]  # fmt: skip
    jacobian_m = (np.swapaxes(_cross_matrices(along), 1, 2) @ position_jacobians
                  + around_p @ jacobian_l)  # fmt: skip
    return lines, np.concatenate((jacobian_l, jacobian_m), axis=1)


def primitive_kinematics(robot: MobileManipulator, q: Array) -> PrimitiveKinematics:
    """The points, segments and their Jacobians of ``robot.collision`` at ``q``."""
    model = robot.collision
    poses, jacobians = robot.frame_kinematics(q)
    positions, position_jacobians = translations(poses), translation_jacobians(poses, jacobians)
    frames = [p.frame for p in model.points]
    points, point_jacobians = positions[frames], position_jacobians[frames]
    for i, point in enumerate(model.points):
        if any(point.offset):
            offset = offset_pose(point)
            pose = dq.mul(poses[point.frame], offset)
            points[i] = dq.translation(pose)
            point_jacobians[i] = translation_jacobian(pose, dq.haminus8(offset)
                                                      @ jacobians[point.frame])  # fmt: skip
    frames = [s.frame for s in model.segments]
    directions = np.array([AXES[s.axis] for s in model.segments]).reshape(-1, 4)
    lines, line_jacobian_stack = line_jacobians(poses[frames], jacobians[frames], directions,
                                                positions[frames], position_jacobians[frames])
    starts = points[[s.start for s in model.segments], 1:]
    ends = points[[s.end for s in model.segments], 1:]
    feet = foot(lines)
    parameters = np.column_stack((((starts - feet) * lines[:, 1:4]).sum(axis=1),
                                  ((ends - feet) * lines[:, 1:4]).sum(axis=1)))  # fmt: skip
    return PrimitiveKinematics(points, point_jacobians, lines, line_jacobian_stack, parameters)
