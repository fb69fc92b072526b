"""Distances between a robot's points and lines and the workspace's planes and lines, and their
Jacobians (Marinho, Adorno et al., T-RO 2019, arXiv 1804.11270, section IV; DQ Robotics'
DQ_Geometry and DQ_Kinematics, whose argument order these follow).

Each Jacobian J_d is a row on q' with d' = J_d q' for a static workspace primitive:

    point to point      D   = ||p - c||^2                             (squared)
                        J_D = 2 vec4(p - c)^T J_t
    point to plane      d   = <p, n> - d_pi                           (signed, > 0 on n's side)
                        J_d = vec4(n)^T J_t
    point to line       D   = ||p x l - m||^2                         (squared)
                        J_D = 2 vec4(p x l - m)^T C4(l)^T J_t
    line to line        D   = a^2 / s                                 (squared)
                        a   = <l, m_z> + <m, l_z> = D(dot(l_, l_z))
                        s   = ||l x l_z||^2 = ||P(cross(l_, l_z))||^2
                        J_D = (2 a / s) (m_z^T J_l + l_z^T J_m)
                              + (2 a^2 / s^2) (l x l_z)^T C4(l_z) J_l

with p the robot's point, J_t its translation Jacobian (4.18), c a workspace point,
n + eps d_pi the plane, l + eps m a line, J_l = [J_l; J_m] the robot line's Jacobian
(``wbc.robot_primitives.line_jacobians``) and l_z + eps m_z the workspace line. Line to line
holds for lines that are not parallel (s > 0).
"""

from __future__ import annotations

import numpy as np

from wbc.plucker import cross3

Array = np.ndarray

PARALLEL = 1e-12
"""s = sin^2 of the angle between two lines below which they count as parallel."""


class ParallelLinesError(ValueError):
    """The line-to-line distance Jacobian was asked for two parallel lines."""


def _rows(weights: Array, translation_jacobian: Array) -> Array:
    """weights^T J_t for one point (4,), (4, n) or row by row for stacks (k, 4), (k, 4, n)."""
    return np.einsum("...i,...in->...n", weights, translation_jacobian)


def point_to_point_squared_distance(point: Array, other: Array) -> Array:
    """||p - c||^2 of two points (vec4), or of stacks of them (k, 4) row by row."""
    difference = point - other
    return (difference * difference).sum(axis=-1)


def point_to_point_distance_jacobian(translation_jacobian: Array, point: Array, other: Array
                                     ) -> Array:  # fmt: skip
    """2 vec4(p - c)^T J_t: the row of D' for the squared distance of the robot's point from
    the workspace point ``other``."""
    return _rows(2.0 * (point - other), translation_jacobian)


def point_to_plane_distance(point: Array, plane: Array) -> Array:
    """<p, n> - d: the signed distance of ``point`` (vec4) from ``plane`` (vec8 n + eps d),
    or of a stack of points (k, 4) from one plane or from a stack of planes (k, 8)."""
    return (point[..., 1:4] * plane[..., 1:4]).sum(axis=-1) - plane[..., 4]


def point_to_plane_distance_jacobian(translation_jacobian: Array, plane: Array) -> Array:
    """vec4(n)^T J_t: the row (n,) of d' for the point whose translation Jacobian (4, n) is
    given, or the rows (k, n) of a stack of them (k, 4, n), against one plane or a stack."""
    return _rows(np.broadcast_to(plane[..., :4], translation_jacobian.shape[:-1]),
                 translation_jacobian)


def _point_line_residual(point: Array, line: Array) -> Array:
    """vec4(p x l - m), of one point or of a stack, from one line or a stack."""
    residual = np.zeros(np.broadcast_shapes(point.shape, line[..., :4].shape))
    residual[..., 1:] = cross3(point[..., 1:4], line[..., 1:4]) - line[..., 5:8]
    return residual


def point_to_line_squared_distance(point: Array, line: Array) -> Array:
    """||p x l - m||^2, the squared distance of ``point`` (vec4) from the Plücker ``line``,
    or of a stack of points (k, 4) from one line or from a stack of lines (k, 8)."""
    residual = _point_line_residual(point, line)
    return (residual * residual).sum(axis=-1)


def point_to_line_distance_jacobian(translation_jacobian: Array, point: Array, line: Array
                                    ) -> Array:  # fmt: skip
    """2 vec4(p x l - m)^T C4(l)^T J_t = 2 vec4(l x (p x l - m))^T J_t: the row of D' for the
    squared distance (of one point, or of stacks as ``point_to_line_squared_distance``)."""
    residual = _point_line_residual(point, line)
    weights = np.zeros(residual.shape)
    weights[..., 1:] = 2.0 * cross3(line[..., 1:4], residual[..., 1:])
    return _rows(weights, translation_jacobian)


def _line_terms(robot_line: Array, workspace_line: Array) -> tuple[float, float, Array]:
    """a = <l, m_z> + <m, l_z>, s = ||l x l_z||^2 and l x l_z (a 3-vector)."""
    a = float(robot_line[1:4] @ workspace_line[5:8] + robot_line[5:8] @ workspace_line[1:4])
    cross = cross3(robot_line[1:4], workspace_line[1:4])
    return a, float(cross @ cross), cross


def line_to_line_squared_distance(robot_line: Array, workspace_line: Array) -> float:
    """a^2 / s for lines that are not parallel; for parallel ones the squared distance
    ||m - <l, l_z> m_z||^2 between them."""
    a, s, _ = _line_terms(robot_line, workspace_line)
    if s > PARALLEL:
        return a * a / s
    b = float(robot_line[:4] @ workspace_line[:4])
    residual = robot_line[4:] - b * workspace_line[4:]
    return float(residual @ residual)


def line_to_line_distance_jacobian(line_jacobian: Array, robot_line: Array,
                                   workspace_line: Array) -> Array:  # fmt: skip
    """The row of D' for the squared distance a^2 / s (module docstring); ``ParallelLinesError``
    for parallel lines, where the distance is not differentiable."""
    a, s, cross = _line_terms(robot_line, workspace_line)
    if s <= PARALLEL:
        raise ParallelLinesError("the line-to-line distance Jacobian needs lines that are not "
                                 f"parallel (sin^2 of their angle is {s:.3g})")  # fmt: skip
    jacobian_l, jacobian_m = line_jacobian[1:4], line_jacobian[5:8]
    lz, mz = workspace_line[1:4], workspace_line[5:8]
    a_rate = mz @ jacobian_l + lz @ jacobian_m
    # s' = 2 <l x l_z, l' x l_z> = -2 (l x l_z)^T C4(l_z) l' = -2 <(l x l_z) x l_z, l'>.
    s_rate = -2.0 * cross3(cross, lz) @ jacobian_l
    return (2.0 * a / s) * a_rate - (a * a / (s * s)) * s_rate
