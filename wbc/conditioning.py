"""How well the whole body can move the end effector in every direction at a configuration.

Under the nonholonomic constraint the base moves as (x', y', phi') = (v cos phi, v sin phi,
omega), so the end-effector pose moves as x' = J N u_eff with u_eff = (v, omega, q2'..q5')
and the effective Jacobian

    J_eff = [J_x cos phi + J_y sin phi, J_phi, J_q2, ..., J_q5]      (8 x 6),

the waist column J_q1 left out because it equals J_phi (the arm stands on the base's turning
axis). A unit dual quaternion has six degrees of freedom, so J_eff has rank 6 at most; its
sixth singular value is 0 at a singularity and measures how far the configuration is from
one.
"""

from __future__ import annotations

import math

import numpy as np

from wbc.robot import MobileManipulator

Array = np.ndarray


def effective_jacobian(robot: MobileManipulator, q: Array) -> Array:
    """J_eff (8 x 6) of the module docstring at configuration q."""
    jacobian = robot.pose_jacobian(q)
    phi = float(q[2])
    forward = jacobian[:, 0] * math.cos(phi) + jacobian[:, 1] * math.sin(phi)
    return np.column_stack((forward, jacobian[:, 2], jacobian[:, 4:]))


def smallest_singular_value(robot: MobileManipulator, q: Array) -> float:
    """sigma_6(J_eff): the conditioning of the whole body at q (0 at a singularity)."""
    return float(np.linalg.svd(effective_jacobian(robot, q), compute_uv=False)[-1])
