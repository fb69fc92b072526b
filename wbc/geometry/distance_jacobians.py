"""Distances between a robot's points and lines and the workspace's planes and lines, and their
Jacobians (Marinho, Adorno et al., T-RO 2019, arXiv 1804.11270, section IV; DQ Robotics'
DQ_Geometry and DQ_Kinematics, whose argument order these follow).

Each Jacobian J_d is a row on q' with d' = J_d q' for a static workspace primitive:

    point to point      D   = ||p - c||^2                             (squared)
                        J_D = 2 vec4(p - c)^T J_t
    point to plane      d   = <p, n> - d_pi                           (signed, > 0 on n's side)
                        J_d = vec4(n)^T J_t
    point to line       D   = ||p x l - m||^2                         (squared)
                        J_D = 2 vec4(p x l - m)^T C4(l)^T J_t = 2 vec4(l x (p x l - m))^T J_t
    line to line        D   = a^2 / s                                 (squared)
                        a   = <l, m_z> + <m, l_z> = D(dot(l_, l_z))
                        s   = ||l x l_z||^2 = ||P(cross(l_, l_z))||^2
                        J_D = (2 a / s) (m_z^T J_l + l_z^T J_m)
                              + (2 a^2 / s^2) (l x l_z)^T C4(l_z) J_l

with p the robot's point, J_t its translation Jacobian (4.18), c a workspace point,
n + eps d_pi the plane, l + eps m a line, J_l = [J_l; J_m] the robot line's Jacobian
(``wbc.geometry.robot_primitives.line_jacobians``) and l_z + eps m_z the workspace line. Line to
line holds for lines that are not parallel (s > 0).

Each Jacobian is a weight vector w times the primitive's Jacobian, J_d = w^T J_t (w = vec4(n),
2 vec4(p - c), 2 vec4(l x (p x l - m))) or w^T J_l (an 8-vector): ``point_to_plane``,
``point_to_line``, ``point_to_point`` and ``line_to_line`` give (distance, w) in Python floats,
the form the rows of ``wbc.laws.constraints.arm_obstacles`` take them in
(``wbc.geometry.wrench_rows`` then multiplies them out without forming J_t or J_l); the
``*_jacobian`` functions multiply them by a part's Jacobian. On 3-vectors Python's float arithmetic
beats numpy's call overhead: a step's point rows against the table (each of 4 points' nearest
feature, distance and weights) take 13 us so, against 85 us as masked arrays times each point's J_t
(CPU time over the states of `parsimony bench`'s reach over the table, the two in turn).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

Array = np.ndarray
Vector = tuple[float, ...]
"""A point (x, y, z), or the weights w of a distance Jacobian, as Python floats."""

PARALLEL = 1e-12
"""s = sin^2 of the angle between two lines below which they count as parallel."""


class ParallelLinesError(ValueError):
    """The line-to-line distance Jacobian was asked for two parallel lines."""


def point_to_point(point: Sequence[float], other: Sequence[float]) -> tuple[float, Vector]:
    """(D, w): D = ||p - c||^2 of the points (x, y, z) and w = 2 (p - c), D' = <w, p'>."""
    dx, dy, dz = point[0] - other[0], point[1] - other[1], point[2] - other[2]
    return dx * dx + dy * dy + dz * dz, (2.0 * dx, 2.0 * dy, 2.0 * dz)


def point_to_plane(point: Sequence[float], plane: Sequence[float]) -> tuple[float, Vector]:
    """(d, n): d = <p, n> - d_pi of the point (x, y, z) from the plane (vec8), d' = <n, p'>."""
    nx, ny, nz = plane[1], plane[2], plane[3]
    return point[0] * nx + point[1] * ny + point[2] * nz - plane[4], (nx, ny, nz)


def point_to_line(point: Sequence[float], line: Sequence[float]) -> tuple[float, Vector]:
    """(D, w): D = ||p x l - m||^2 of the point (x, y, z) from the Plücker line (vec8) and
    w = 2 l x (p x l - m), D' = <w, p'>."""
    px, py, pz = point[0], point[1], point[2]
    lx, ly, lz = line[1], line[2], line[3]
    rx = py * lz - pz * ly - line[5]
    ry = pz * lx - px * lz - line[6]
    rz = px * ly - py * lx - line[7]
    return rx * rx + ry * ry + rz * rz, (
        2.0 * (ly * rz - lz * ry),
        2.0 * (lz * rx - lx * rz),
        2.0 * (lx * ry - ly * rx),
    )


def line_to_line(
    robot_line: Sequence[float], workspace_line: Sequence[float]
) -> tuple[float, Vector]:
    """(D, w): D = a^2 / s of two lines (vec8) that are not parallel, and the 8 weights w with
    D' = w^T vec8(l_') (module docstring): w = [0, (2 a / s) m_z + (2 a^2 / s^2) (l x l_z) x
    l_z, 0, (2 a / s) l_z]. ``ParallelLinesError`` for parallel lines, where D is not
    differentiable."""
    lx, ly, lz, mx, my, mz = (robot_line[i] for i in (1, 2, 3, 5, 6, 7))
    zx, zy, zz, nx, ny, nz = (workspace_line[i] for i in (1, 2, 3, 5, 6, 7))
    a = lx * nx + ly * ny + lz * nz + mx * zx + my * zy + mz * zz
    cx, cy, cz = ly * zz - lz * zy, lz * zx - lx * zz, lx * zy - ly * zx  # l x l_z
    s = cx * cx + cy * cy + cz * cz
    if s <= PARALLEL:
        raise ParallelLinesError(
            "the line-to-line distance Jacobian needs lines that are not "
            f"parallel (sin^2 of their angle is {s:.3g})"
        )
    # s' = 2 <l x l_z, l' x l_z> = -2 <(l x l_z) x l_z, l'>, and D' = (2 a a' s - a^2 s') / s^2.
    first, second = 2.0 * a / s, 2.0 * a * a / (s * s)
    return a * a / s, (
        0.0,
        first * nx + second * (cy * zz - cz * zy),
        first * ny + second * (cz * zx - cx * zz),
        first * nz + second * (cx * zy - cy * zx),
        0.0,
        first * zx,
        first * zy,
        first * zz,
    )


def _jacobian(weights: Vector, jacobian: Array) -> Array:
    """w^T J for 3 weights on the rows 1-3 of a translation Jacobian (4, n), or 8 on the rows of
    a line Jacobian (8, n)."""
    rows = jacobian[1:4] if len(weights) == 3 else jacobian
    return np.asarray(weights) @ rows


def point_to_point_squared_distance(point: Array, other: Array) -> float:
    """||p - c||^2 of two points (vec4)."""
    return point_to_point(point[1:4], other[1:4])[0]


def point_to_point_distance_jacobian(
    translation_jacobian: Array, point: Array, other: Array
) -> Array:
    """2 vec4(p - c)^T J_t: the row of D' for the squared distance of the robot's point (vec4)
    from the workspace point ``other`` (vec4)."""
    return _jacobian(point_to_point(point[1:4], other[1:4])[1], translation_jacobian)


def point_to_plane_distance(point: Array, plane: Array) -> float:
    """<p, n> - d: the signed distance of ``point`` (vec4) from ``plane`` (vec8 n + eps d)."""
    return point_to_plane(point[1:4], plane)[0]


def point_to_plane_distance_jacobian(translation_jacobian: Array, plane: Array) -> Array:
    """vec4(n)^T J_t: the row (n,) of d' for the point whose translation Jacobian (4, n) is
    given."""
    return _jacobian(tuple(plane[1:4]), translation_jacobian)


def point_to_line_squared_distance(point: Array, line: Array) -> float:
    """||p x l - m||^2, the squared distance of ``point`` (vec4) from the Plücker ``line``."""
    return point_to_line(point[1:4], line)[0]


def point_to_line_distance_jacobian(
    translation_jacobian: Array, point: Array, line: Array
) -> Array:
    """2 vec4(p x l - m)^T C4(l)^T J_t = 2 vec4(l x (p x l - m))^T J_t: the row of D' for the
    squared distance of ``point`` (vec4) from ``line``."""
    return _jacobian(point_to_line(point[1:4], line)[1], translation_jacobian)


def line_to_line_squared_distance(robot_line: Array, workspace_line: Array) -> float:
    """a^2 / s for lines that are not parallel; for parallel ones the squared distance
    ||m - <l, l_z> m_z||^2 between them."""
    try:
        return line_to_line(robot_line, workspace_line)[0]
    except ParallelLinesError:
        b = float(robot_line[:4] @ workspace_line[:4])
        residual = robot_line[4:] - b * workspace_line[4:]
        return float(residual @ residual)


def line_to_line_distance_jacobian(
    line_jacobian: Array, robot_line: Array, workspace_line: Array
) -> Array:
    """The row of D' for the squared distance a^2 / s (module docstring); ``ParallelLinesError``
    for parallel lines, where the distance is not differentiable."""
    return _jacobian(line_to_line(robot_line, workspace_line)[1], line_jacobian)
