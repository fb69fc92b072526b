"""A whole-body configuration of a pose goal: bounded inverse kinematics from one start.

A staging candidate (``wbc.planning.staging``) is a whole configuration q_c with
fkm(q_c) = x_d, found by a bounded least-squares search from a start:

    min ||vec8(fkm(q)) - vec8(x_d)||^2  over  z = (x, y, phi, q2, ..., qn),  q1 = 0,

each arm joint kept inside the search's box (``arm_box``: the LP's joint box b_l [q-, q+] (5.14)
shrunk by a margin). The waist is held at 0: it turns the arm exactly as phi does (the arm stands
on the base's turning axis), so the base's heading carries the arm's yaw.
"""

from __future__ import annotations

import math

import numpy as np

from wbc import dq
from wbc.planar import wrap
from wbc.robot import BASE_DOF, MobileManipulator

Array = np.ndarray


def free_entries(dof: int) -> list[int]:
    """The entries of q (``dof`` of them) the search moves: the base and every arm joint but
    the waist."""
    return [*range(BASE_DOF), *range(BASE_DOF + 1, dof)]


def arm_box(robot: MobileManipulator, safety_factor: float, margin: float) -> tuple[Array, Array]:
    """The arm joints' search bounds: b_l [q-, q+] shrunk by ``margin`` on each side."""
    low, high = robot.joint_box(safety_factor)
    return low[BASE_DOF:] + margin, high[BASE_DOF:] - margin


def solve_ik(
    robot: MobileManipulator,
    goal_pose: Array,
    start: Array,
    bounds: tuple[Array, Array],
    tolerance: float,
) -> Array | None:
    """A configuration q (q1 = 0) with fkm(q) = goal_pose from ``start``, or None."""
    from scipy.optimize import least_squares  # loaded by the first plan: see ``staging.plan``

    q = np.array(start, dtype=float)
    q[BASE_DOF] = 0.0
    free = free_entries(robot.dof)
    goal = dq.nearest_equivalent(goal_pose, robot.fkm(q))

    def residual(z: Array) -> Array:
        q[free] = z
        return robot.fkm(q) - goal

    def jacobian(z: Array) -> Array:
        q[free] = z
        return robot.pose_jacobian(q)[:, free]

    result = least_squares(
        residual,
        q[free],
        jac=jacobian,
        bounds=bounds,
        method="trf",
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-12,
        max_nfev=200,
    )
    if not math.sqrt(2.0 * result.cost) < tolerance:
        return None
    q[free] = result.x
    q[2] = wrap(q[2])
    return q.copy()
