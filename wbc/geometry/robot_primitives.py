"""Where the robot's collision parts (``wbc.collision_model``) are at one configuration, and
their Jacobians.

For a point at ``offset`` in frame i: x = x_i (1 + eps offset / 2), at p = t_i + r_i offset r_i*
(t_i = 2 D(x_i) P(x_i)*, 4.12), its pose Jacobian H-(1 + eps offset / 2) J_i and its translation
Jacobian J_t (4.18), J_i the pose Jacobian of frame i (``MobileManipulator.frame_kinematics``:
the columns of the joints after frame i are 0). For a segment on the axis a of frame i: its
Plücker line l + eps t_i x l with l = r a r* and the line Jacobian of DQ Robotics'
``line_jacobian`` (``line_jacobians``; Marinho et al. eq. 26-28), and its ends as parameters s
along the line, p_0 + s l with p_0 = l x m (so s = <p, l> at an end p).

The positions come from the step's forward pass in Python floats (4 points and 2 lines: 13 us
of CPU, where the array forms took 34 us). The rows of ``wbc.laws.constraints.arm_obstacles`` need
no more: ``wbc.geometry.wrench_rows`` forms them from the twists; J_t and J_l here are what those
rows are held to (tests/wbc/geometry/test_wrench_rows.py).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np

from wbc import dq
from wbc.collision_model import AXES, offset_pose
from wbc.geometry.distance_jacobians import Vector
from wbc.robot import Chain, MobileManipulator, translation_jacobian

Array = np.ndarray

_CONJ4 = np.array([1.0, -1.0, -1.0, -1.0])


def translations(poses: Array) -> Array:
    """p = 2 D(x) P(x)* (4.12) of each pose of a stack (k, 8): (k, 4)."""
    return 2.0 * (dq.hamiplus4_stack(poses[:, 4:]) @ (poses[:, :4] * _CONJ4)[:, :, None])[:, :, 0]


def translation_jacobians(poses: Array, jacobians: Array) -> Array:
    """J_t = 2 H-_4(P(x*)) J_D + 2 H+_4(D(x)) C4 J_P (4.18) of each pose of a stack: (k, 4, n)."""
    conjugates = poses[:, :4] * _CONJ4
    return 2.0 * (
        dq.haminus4_stack(conjugates) @ jacobians[:, 4:]
        + dq.hamiplus4_stack(poses[:, 4:]) @ (jacobians[:, :4] * _CONJ4[:, None])
    )


_CROSS_INDEX = np.array([[0, 0, 0, 0], [0, 0, 3, 2], [0, 3, 0, 1], [0, 2, 1, 0]])
_CROSS_SIGN = np.array([[0.0, 0, 0, 0], [0, 0, -1, 1], [0, 1, 0, -1], [0, -1, 1, 0]])


def _cross_matrices(vectors: Array) -> Array:
    """C4 (``wbc.geometry.plucker.crossmatrix4``) of each pure quaternion of a stack: (k, 4, 4)."""
    return vectors[:, _CROSS_INDEX] * _CROSS_SIGN


def line_jacobians(
    poses: Array, jacobians: Array, directions: Array, positions: Array, position_jacobians: Array
) -> tuple[Array, Array]:
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
    jacobian_l = (
        dq.haminus4_stack(direction_conj) + dq.hamiplus4_stack(along_r) * _CONJ4
    ) @ jacobians[:, :4]
    jacobian_m = (
        np.swapaxes(_cross_matrices(along), 1, 2) @ position_jacobians + around_p @ jacobian_l
    )
    return lines, np.concatenate((jacobian_l, jacobian_m), axis=1)


def _translation(pose: Sequence[float]) -> Vector:
    """t = 2 D(x) P(x)* (4.12) of a pose (vec8), as (x, y, z): with P = (p0, p) and
    D = (d0, d), t = 2 (p0 d - d0 p - d x p)."""
    p0, p1, p2, p3, d0, d1, d2, d3 = pose
    return (
        2.0 * (p0 * d1 - d0 * p1 - d2 * p3 + d3 * p2),
        2.0 * (p0 * d2 - d0 * p2 - d3 * p1 + d1 * p3),
        2.0 * (p0 * d3 - d0 * p3 - d1 * p2 + d2 * p1),
    )


def _rotated(pose: Sequence[float], vector: Sequence[float]) -> Vector:
    """r v r* of a 3-vector v by the rotation r = (w, a) of a pose: v + 2 w (a x v) +
    2 a x (a x v)."""
    w, ax, ay, az = pose[0], pose[1], pose[2], pose[3]
    vx, vy, vz = vector
    cx, cy, cz = ay * vz - az * vy, az * vx - ax * vz, ax * vy - ay * vx
    return (
        vx + 2.0 * (w * cx + ay * cz - az * cy),
        vy + 2.0 * (w * cy + az * cx - ax * cz),
        vz + 2.0 * (w * cz + ax * cy - ay * cx),
    )


class PrimitiveKinematics:
    """Where the parts are at one configuration (Python floats, and arrays when asked), and
    their Jacobians J_t and J_l (4.18 and DQ Robotics' line Jacobian) when asked. The rows of
    ``wbc.laws.constraints.arm_obstacles`` need only where they are
    (``wbc.geometry.wrench_rows``)."""

    def __init__(self, robot: MobileManipulator, chain: Chain) -> None:
        model = robot.collision
        self.robot, self.chain = robot, chain
        poses = chain.poses.tolist()
        origins: dict[int, Vector] = {}
        for part in (*model.points, *model.segments):
            if part.frame not in origins:
                origins[part.frame] = _translation(poses[part.frame])
        self.positions: list[Vector] = []
        """Each point (x, y, z): the origin of its frame moved by r offset r*."""
        for point in model.points:
            origin = origins[point.frame]
            if any(point.offset):
                moved = _rotated(poses[point.frame], point.offset)
                origin = (origin[0] + moved[0], origin[1] + moved[1], origin[2] + moved[2])
            self.positions.append(origin)
        self.point_frames = [p.frame for p in model.points]
        self.segment_frames = [s.frame for s in model.segments]
        self.line_list: list[Vector] = []
        """Each segment's Plücker line l + eps p x l, l = r a r* (vec8)."""
        self.end_list: list[tuple[float, float]] = []
        """Each segment's ends as p_0 + s l along its line: s = <p, l> at its end points p."""
        for segment in model.segments:
            (px, py, pz), (sx, sy, sz), (ex, ey, ez) = (
                origins[segment.frame],
                self.positions[segment.start],
                self.positions[segment.end],
            )
            lx, ly, lz = _rotated(poses[segment.frame], AXES[segment.axis][1:])
            self.line_list.append(
                (0.0, lx, ly, lz, 0.0, py * lz - pz * ly, pz * lx - px * lz, px * ly - py * lx)
            )
            self.end_list.append((sx * lx + sy * ly + sz * lz, ex * lx + ey * ly + ez * lz))

    @functools.cached_property
    def points(self) -> Array:
        """(k, 4) pure quaternions."""
        return np.hstack(
            (np.zeros((len(self.positions), 1)), np.array(self.positions).reshape(-1, 3))
        )

    @functools.cached_property
    def lines(self) -> Array:
        """(s, 8) Plücker lines of the segments."""
        return np.array(self.line_list).reshape(-1, 8)

    @functools.cached_property
    def ends(self) -> Array:
        """(s, 2): each segment's ends as p_0 + s l along its line, p_0 = l x m."""
        return np.array(self.end_list).reshape(-1, 2)

    @functools.cached_property
    def point_jacobians(self) -> Array:
        """(k, 4, dof) translation Jacobians (4.18)."""
        poses, jacobians = self.chain.poses, self.chain.frame_jacobians
        stack = translation_jacobians(poses[self.point_frames], jacobians[self.point_frames])
        for i, point in enumerate(self.robot.collision.points):
            if any(point.offset):
                offset = offset_pose(point)
                stack[i] = translation_jacobian(
                    dq.mul(poses[point.frame], offset), dq.haminus8(offset) @ jacobians[point.frame]
                )
        return stack

    @functools.cached_property
    def line_jacobians(self) -> Array:
        """(s, 8, dof), DQ Robotics' line Jacobians (``line_jacobians``)."""
        frames = self.segment_frames
        poses, jacobians = self.chain.poses[frames], self.chain.frame_jacobians[frames]
        directions = np.array([AXES[s.axis] for s in self.robot.collision.segments])
        return line_jacobians(
            poses,
            jacobians,
            directions.reshape(-1, 4),
            translations(poses),
            translation_jacobians(poses, jacobians),
        )[1]


def primitive_kinematics(
    robot: MobileManipulator, q: Array, chain: Chain | None = None
) -> PrimitiveKinematics:
    """The points, segments and their Jacobians of ``robot.collision`` at ``q``, from the
    forward pass ``chain`` at q when the step has one (``MobileManipulator.forward``)."""
    return PrimitiveKinematics(robot, robot.forward(q) if chain is None else chain)
