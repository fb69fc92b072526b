"""The row on u of a distance between a robot's part and a static obstacle, from the twists of
the forward pass: no part's Jacobian is formed.

Column c of the twists T (8, dof) of ``MobileManipulator.forward`` is (1/2)(w_c + eps v_c):
u = e_c moves the robot's frames rigidly, at angular velocity w_c and with velocity v_c at the
world's origin (joint j about its axis line l_j + eps m_j: w = l_j, v = m_j). A point p and a
Plücker line l + eps m fixed in frame i then move at

    p' = sum_c (w_c x p + v_c) u_c,   l' = sum_c (w_c x l) u_c,   m' = sum_c (v_c x l + w_c x m) u_c

over the columns c that move frame i (the base's and joints 1..i). A distance whose rate is
<g, p'>, or <g_l, l'> + <g_m, m'> (the weights of ``wbc.geometry.distance_jacobians``), has the row

    J_d = 2 [0, (p x g)^T, 0, g^T] T                              (a point)
    J_d = 2 [0, (l x g_l + m x g_m)^T, 0, (l x g_m)^T] T          (a line)

with the columns after frame i zero: the gradient's wrench (a vec8 like T's columns) times the
twists. It equals w^T J_t with J_t of 4.18 and w^T J_l with DQ Robotics' line Jacobian, ours
(``wbc.geometry.robot_primitives``) and DQ Robotics' own (tests/wbc/geometry/test_wrench_rows.py).
Every row of a step is then one (rows, 8) x (8, dof) product, 6.5 us of CPU, where forming
each part's J_t and J_l from the frames' Jacobians takes 95-100 us (over the states of
`parsimony bench`'s reach over the table).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from wbc.geometry.distance_jacobians import Vector
from wbc.robot import Chain

Array = np.ndarray


def point_wrench(point: Sequence[float], weights: Sequence[float]) -> Vector:
    """(0, p x g, 0, g) for the weights g (3) of a distance's rate <g, p'> at the point p
    (3)."""
    px, py, pz = point[0], point[1], point[2]
    gx, gy, gz = weights[0], weights[1], weights[2]
    return (0.0, py * gz - pz * gy, pz * gx - px * gz, px * gy - py * gx, 0.0, gx, gy, gz)


def line_wrench(line: Sequence[float], weights: Sequence[float]) -> Vector:
    """(0, l x g_l + m x g_m, 0, l x g_m) for the weights (g_l, g_m) (rows 1-3 and 5-7 of an
    8-vector) of a distance's rate <g_l, l'> + <g_m, m'> at the line l + eps m (vec8)."""
    lx, ly, lz, mx, my, mz = (line[i] for i in (1, 2, 3, 5, 6, 7))
    ax, ay, az, bx, by, bz = (weights[i] for i in (1, 2, 3, 5, 6, 7))
    fx, fy, fz = ly * bz - lz * by, lz * bx - lx * bz, lx * by - ly * bx
    return (
        0.0,
        ly * az - lz * ay + my * bz - mz * by,
        lz * ax - lx * az + mz * bx - mx * bz,
        lx * ay - ly * ax + mx * by - my * bx,
        0.0,
        fx,
        fy,
        fz,
    )


def wrench_rows(chain: Chain, wrenches: Sequence[Vector], frames: Sequence[int]) -> Array:
    """The rows J_d (len(wrenches), dof) of the module's docstring, each wrench (vec8) on the
    frame of the same index in ``frames``."""
    rows = 2.0 * (np.array(wrenches) @ chain.twists)
    rows *= chain.columns[frames, 0]
    return rows
