"""The classic whole-body law u = -J^+ eta e (5.3): holonomic, continuous, uses every joint.

With ``nonholonomic`` it takes the pseudoinverse of the Jacobian of the velocities 5.11
allows instead: u = N (J N)^+ (-eta e), the columns of N an orthonormal basis of them (the
base's forward speed along its heading, its yaw, the arm joints). Not in the dissertation: it
is the least 2-norm u the nonholonomic robot can take for the task, the 2-norm baseline the
cascade of appendix B only approximates (table 6.1's metric 2). A fixed base's u_b is 0 (the
pseudoinverse of the arm's columns); an omnidirectional base has no 5.11 to obey.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from wbc.geometry.obstacles import Obstacle
from wbc.laws.gains import check_gains, gain
from wbc.laws.law_output import LawOutput, summarise
from wbc.robot import BASE_DOF, MobileManipulator
from wbc.task import Task
from wbc.validation import require_finite

Array = np.ndarray

PINV_RCOND = 1e-9
"""Singular values below this fraction of the largest are dropped (J of a pose task is rank 6)."""


def pinv_velocity(task_jacobian: Array, error: Array, eta: float) -> Array:
    """u = -J^+ eta e (5.3)."""
    return -eta * (np.linalg.pinv(task_jacobian, rcond=PINV_RCOND) @ error)


def velocity_basis(robot: MobileManipulator, phi: float, nonholonomic: bool) -> Array | None:
    """N spanning the u the robot's base allows (None: every u): a fixed base's arm joints
    alone; a differential base's under 5.11 when ``nonholonomic``; an omnidirectional base's
    every u, whatever ``nonholonomic``."""
    if robot.base.kind == "fixed":
        return np.eye(robot.dof)[:, BASE_DOF:]
    if nonholonomic and robot.base.kind == "differential":
        return nonholonomic_basis(phi, robot.dof)
    return None


def nonholonomic_basis(phi: float, dof: int) -> Array:
    """N: orthonormal columns spanning the u that obey 5.11 at heading phi: (cos phi, sin phi)
    on x', y', then one column for phi' and each arm joint."""
    basis = np.zeros((dof, dof - 1))
    basis[0, 0], basis[1, 0] = math.cos(phi), math.sin(phi)
    basis[2:, 1:] = np.eye(dof - 2)
    return basis


@dataclass(frozen=True)
class PinvParams:
    eta: float = gain(0.6, low=1e-3, high=100.0, doc="task gain, 1/s")
    nonholonomic: bool = gain(False, doc="the pseudoinverse of J N, N spanning what 5.11 allows")

    def __post_init__(self) -> None:
        check_gains(self)


@dataclass
class PseudoinverseLaw:
    """u = -J^+ eta e (5.3, B.1) with the holonomic base model of eq. 4.3, or under 5.11 with
    ``nonholonomic``; no other constraint."""

    robot: MobileManipulator
    params: PinvParams = field(default_factory=PinvParams)

    def set_params(self, params: PinvParams) -> None:
        self.params = params

    def reset(self) -> None:
        """Stateless: nothing to forget."""

    def stopped(self) -> None:
        """Stateless: nothing to forget."""

    def step(
        self, q: Array, task: Task, dt: float, obstacles: Sequence[Obstacle] = ()
    ) -> LawOutput:
        """One step; ``dt`` and ``obstacles`` are accepted for a common signature and unused."""
        start = time.perf_counter()
        q = require_finite("configuration q", q)
        pose, jacobian = self.robot.kinematics(q)
        error, task_jacobian = task.error(pose, jacobian, q)
        basis = velocity_basis(self.robot, float(q[2]), self.params.nonholonomic)
        if basis is not None:
            u = basis @ pinv_velocity(task_jacobian @ basis, error, self.params.eta)
        else:
            u = pinv_velocity(task_jacobian, error, self.params.eta)
        return summarise(u, "optimal", None, (), error, start)
