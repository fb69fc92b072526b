"""Tasks on the base and the arm's joints, for the legs of a staging plan (wbc.planning.staging).

A differential-drive base cannot steer its wheel axle's centre, but it can steer a point
ahead of it: p = (x + d cos phi, y + d sin phi) moves as

    p' = [cos phi, sin phi] v + d [-sin phi, cos phi] phi'

for forward speed v, a map that is invertible for d > 0. ``PointTask`` drives p to a point
with e = [p - p_d, q_a - q_a,d] (2 + n rows: the base's two and the n joints' of the arm),
which the robot's 2 + n velocities (v, phi', q1'..qn') meet exactly. ``HeadingTask`` turns
the base in place, e = [wrap(phi - phi_d), q_a - q_a,d]: with its 1 + n rows the forward
speed stays free and the least-velocity term keeps it at zero. Each Jacobian is the
derivative of its error with respect to q = [x, y, phi, q1..qn]; n is the length of the
task's arm configuration (the robot's joints).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wbc.planar import wrap
from wbc.robot import BASE_DOF
from wbc.task import frozen_vector
from wbc.validation import require_finite

Array = np.ndarray


def arm_configuration(values: object) -> Array:
    """A read-only arm configuration: one or more finite joint positions."""
    array = require_finite("arm configuration", values)
    if array.ndim != 1 or array.size == 0:
        raise ValueError(f"arm configuration must be a vector of joints, got shape {array.shape}")
    return frozen_vector("arm configuration", array, array.size)


def _arm_rows(q: Array, arm: Array) -> tuple[Array, Array]:
    """q_a - q_a,d and its Jacobian [0 I]; ``q`` must have the arm's joints."""
    if q.shape != (BASE_DOF + arm.size,):
        raise ValueError(f"q has {q.size} entries, the task's arm {arm.size} joints")
    rows = np.zeros((arm.size, BASE_DOF + arm.size))
    rows[:, BASE_DOF:] = np.eye(arm.size)
    return q[BASE_DOF:] - arm, rows


def offset_point(q: Array, lookahead: float) -> Array:
    """p = (x + d cos phi, y + d sin phi): the point ``lookahead`` d ahead of the axle."""
    phi = float(q[2])
    return np.array([q[0] + lookahead * math.cos(phi), q[1] + lookahead * math.sin(phi)])


@dataclass(frozen=True)
class PointTask:
    """Drive the point ``lookahead`` ahead of the axle to ``point`` (x, y) with the arm going
    to ``arm`` (a position per joint): e = [p - p_d, q_a - q_a,d]."""

    point: Array
    arm: Array
    lookahead: float = 0.1

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", frozen_vector("drive point", self.point, 2))
        object.__setattr__(self, "arm", arm_configuration(self.arm))
        if not self.lookahead > 0.0:
            raise ValueError(f"lookahead must be > 0, got {self.lookahead}")

    @property
    def dof(self) -> int:
        return 2 + self.arm.size

    @property
    def goal_position(self) -> Array:
        return np.array([self.point[0], self.point[1], 0.0])

    @property
    def coefficients(self) -> Array:
        return np.concatenate((self.point, self.arm))

    def error(self, pose: Array, jacobian: Array, q: Array) -> tuple[Array, Array]:
        phi = float(q[2])
        point_rows = np.zeros((2, BASE_DOF + self.arm.size))
        point_rows[0, 0] = point_rows[1, 1] = 1.0
        point_rows[0, 2] = -self.lookahead * math.sin(phi)
        point_rows[1, 2] = self.lookahead * math.cos(phi)
        arm_error, arm_rows = _arm_rows(q, self.arm)
        error = np.concatenate((offset_point(q, self.lookahead) - self.point, arm_error))
        return error, np.vstack((point_rows, arm_rows))


@dataclass(frozen=True)
class HeadingTask:
    """Turn the base to ``heading`` (rad) where it stands, ``position`` (x, y), with the arm
    going to ``arm``: e = [wrap(phi - phi_d), q_a - q_a,d]."""

    heading: float
    arm: Array
    position: Array

    def __post_init__(self) -> None:
        require_finite("heading", np.array([self.heading]))
        object.__setattr__(self, "arm", arm_configuration(self.arm))
        object.__setattr__(self, "position", frozen_vector("turning position", self.position, 2))

    @property
    def dof(self) -> int:
        return 1 + self.arm.size

    @property
    def goal_position(self) -> Array:
        return np.array([self.position[0], self.position[1], 0.0])

    @property
    def coefficients(self) -> Array:
        return np.concatenate(([self.heading], self.arm))

    def error(self, pose: Array, jacobian: Array, q: Array) -> tuple[Array, Array]:
        heading_row = np.zeros((1, BASE_DOF + self.arm.size))
        heading_row[0, 2] = 1.0
        arm_error, arm_rows = _arm_rows(q, self.arm)
        error = np.concatenate(([wrap(float(q[2]) - self.heading)], arm_error))
        return error, np.vstack((heading_row, arm_rows))
