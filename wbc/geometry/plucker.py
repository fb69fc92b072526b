"""Plücker lines and planes as dual quaternions (Marinho, Adorno et al., T-RO 2019, arXiv
1804.11270, section III; DQ Robotics). The Jacobian of a line on the robot is
``wbc.geometry.robot_primitives.line_jacobians``.

A line through the point p with unit direction l (pure quaternions) is l_ = l + eps m with the
moment m = p x l. A plane with unit normal n whose points p satisfy <p, n> = d is pi = n + eps d
(d the signed distance of the plane from the origin along n). Points are pure quaternions
``[0, x, y, z]`` (vec4) or 3-vectors where a function says so.
"""

from __future__ import annotations

import numpy as np

Array = np.ndarray


def pure(vector: Array) -> Array:
    """The pure quaternion [0, v] of a 3-vector (a pure quaternion is returned as it is)."""
    v = np.asarray(vector, dtype=float)
    return v if v.shape == (4,) else np.concatenate(([0.0], v))


def line(direction: Array, point: Array) -> Array:
    """vec8 of the Plücker line l + eps (p x l) through ``point`` along ``direction`` (made
    unit)."""
    unit = pure(direction)
    unit = unit / np.linalg.norm(unit[1:])
    return np.concatenate((unit, crossmatrix4(pure(point)) @ unit))


def plane(normal: Array, offset: float) -> Array:
    """vec8 of the plane n + eps d of unit ``normal`` n and ``offset`` d: <p, n> = d on it."""
    n = pure(normal)
    return np.concatenate((n, [float(offset), 0.0, 0.0, 0.0]))


def crossmatrix4(a: Array) -> Array:
    """C4(a) with vec4(cross(a, b)) = C4(a) vec4(b) for pure quaternions (DQ Robotics'
    ``crossmatrix4``): the skew matrix of Im(a) in the lower 3 x 3 block."""
    _, x, y, z = a
    return np.array([[0.0, 0.0, 0.0, 0.0], [0.0, 0.0, -z, y], [0.0, z, 0.0, -x], [0.0, -y, x, 0.0]])


def is_line(x: Array, tol: float = 1e-9) -> bool:
    """True for a Plücker line: pure primary and dual parts, |l| = 1 and <l, m> = 0."""
    x = np.asarray(x, dtype=float)
    return bool(
        abs(x[0]) < tol
        and abs(x[4]) < tol
        and abs(np.linalg.norm(x[1:4]) - 1.0) < tol
        and abs(float(x[1:4] @ x[5:8])) < tol
    )


def closest_parameters(first: Array, second: Array) -> tuple[Array, Array, Array]:
    """(s, t, c) for the lines ``first`` (8,) or (j, 8) and ``second`` (8,) or (k, 8), each of
    shape (j, k) (j = 1 or k = 1 for a single line): the closest points are p1 + s l1 and
    p2 + t l2, with p_i = l_i x m_i the point of line i nearest the origin, and
    c = 1 - <l1, l2>^2 = ||l1 x l2||^2 (0 for parallel lines, which have no unique pair: s and
    t are then not finite).

    With w = p1 - p2, b = <l1, l2>: s = (b <l2, w> - <l1, w>) / c and
    t = (<l2, w> - b <l1, w>) / c (the normal equations of min ||p1 + s l1 - p2 - t l2||^2).
    """
    first, second = first.reshape(-1, 8), second.reshape(-1, 8)
    l1, l2 = first[:, 1:4], second[:, 1:4]
    p1, p2 = foot(first), foot(second)
    b = l1 @ l2.T
    c = 1.0 - b * b
    # <l1, w> and <l2, w> with w = p1 - p2, for every pair.
    d = (l1 * p1).sum(axis=1)[:, None] - l1 @ p2.T
    e = p1 @ l2.T - (l2 * p2).sum(axis=1)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        return (b * e - d) / c, (e - b * d) / c, c


def foot(x: Array) -> Array:
    """The point l x m of the line ``x`` (8,) nearest the origin (a 3-vector), or of each
    line of ``x`` (k, 8), (k, 3)."""
    return cross3(x[..., 1:4], x[..., 5:8])


_NEXT, _AFTER = np.array([1, 2, 0]), np.array([2, 0, 1])


def cross3(a: Array, b: Array) -> Array:
    """a x b of 3-vectors (..., 3), componentwise a_(i+1) b_(i+2) - a_(i+2) b_(i+1): numpy's
    ``cross`` costs several times as much at this size."""
    return a[..., _NEXT] * b[..., _AFTER] - a[..., _AFTER] * b[..., _NEXT]
