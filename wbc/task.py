"""Tasks: the error and the task Jacobian that every law drives to zero (5.1, 4.18).

The pose task uses e = vec8(x - x_d) with the 8 x n Jacobian J (4.9); the position task uses
e = p - p_d with the rows of the translation Jacobian J_p (4.18) for i, j and k.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from wbc import dq
from wbc.robot import translation_jacobian
from wbc.validation import require_finite

Array = np.ndarray


def frozen_vector(name: str, values: object, size: int) -> Array:
    """A read-only copy of ``values`` as a finite float vector of ``size`` entries, or an error
    naming ``name``: a task's goal cannot change under it."""
    array = require_finite(name, values).copy()
    if array.shape != (size,):
        raise ValueError(f"{name} must have shape ({size},), got {array.shape}")
    array.flags.writeable = False
    return array


@dataclass(frozen=True)
class PoseTask:
    """Drive the end-effector pose to the unit dual quaternion ``pose`` (6 DOF)."""

    pose: Array
    goal_position: Array = field(init=False, repr=False, compare=False)
    """The goal's translation (x, y, z)."""
    dof = 6

    def __post_init__(self) -> None:
        pose = require_finite("goal pose", self.pose).copy()
        if pose.shape != (8,) or not dq.is_unit(pose, 1e-6):
            raise ValueError(f"goal pose must be a unit dual quaternion (8,), got {pose}")
        pose.flags.writeable = False
        object.__setattr__(self, "pose", pose)
        position = dq.translation(pose)[1:]
        position.flags.writeable = False
        object.__setattr__(self, "goal_position", position)

    @property
    def coefficients(self) -> Array:
        return self.pose

    def error(self, pose: Array, jacobian: Array, q: Array | None = None) -> tuple[Array, Array]:
        """(vec8(x - x_d), J), x_d taken with the sign nearer to x (x_d and -x_d are one pose)."""
        return pose - dq.nearest_equivalent(self.pose, pose), jacobian


@dataclass(frozen=True)
class PositionTask:
    """Drive the end-effector position to ``position`` = (x, y, z), orientation free (3 DOF)."""

    position: Array
    dof = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", frozen_vector("goal position", self.position, 3))

    @property
    def goal_position(self) -> Array:
        return self.position

    @property
    def coefficients(self) -> Array:
        return self.position

    def error(self, pose: Array, jacobian: Array, q: Array | None = None) -> tuple[Array, Array]:
        """(p - p_d, rows i, j, k of J_p) (4.18)."""
        return dq.translation(pose)[1:] - self.position, translation_jacobian(pose, jacobian)[1:]


class Task(Protocol):
    """What every law drives to zero: e and its Jacobian at the pose x, Jacobian J and
    configuration q (end-effector tasks use x and J; base and joint tasks use q)."""

    dof: int

    @property
    def goal_position(self) -> Array:
        """Where the task leads, (x, y, z): its projection on the floor is the q_d of 5.25."""
        ...

    @property
    def coefficients(self) -> Array:
        """The goal's numbers: two tasks of one kind are one task when these agree."""
        ...

    def error(self, pose: Array, jacobian: Array, q: Array) -> tuple[Array, Array]: ...


MEASUREMENT_TOLERANCE = 0.02
"""Goals whose coefficients differ by less than this are one task measured twice (a goal the
camera measures each frame): laws keep their state across them."""


def same_task(a: Task, b: Task, tolerance: float = 0.0) -> bool:
    """True when a and b are the same kind of task with goals no further apart than
    ``tolerance`` in any coefficient (0: the same goal)."""
    if a is b:
        return True
    if type(a) is not type(b):
        return False
    return bool(np.max(np.abs(a.coefficients - b.coefficients)) <= tolerance)
