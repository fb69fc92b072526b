"""The classic whole-body law u = -J^+ eta e (5.3): holonomic, continuous, uses every joint."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from wbc.gains import check_gains, gain
from wbc.law_output import LawOutput, summarise
from wbc.obstacles import Circle
from wbc.robot import MobileManipulator
from wbc.task import Task
from wbc.validation import require_finite

Array = np.ndarray

PINV_RCOND = 1e-9
"""Singular values below this fraction of the largest are dropped (J of a pose task is rank 6)."""


def pinv_velocity(task_jacobian: Array, error: Array, eta: float) -> Array:
    """u = -J^+ eta e (5.3)."""
    return -eta * (np.linalg.pinv(task_jacobian, rcond=PINV_RCOND) @ error)


@dataclass(frozen=True)
class PinvParams:
    eta: float = gain(0.6, low=1e-3, high=100.0, doc="task gain, 1/s")

    def __post_init__(self) -> None:
        check_gains(self)


@dataclass
class PseudoinverseLaw:
    """u = -J^+ eta e (5.3, B.1) with the holonomic base model of eq. 4.3; no constraints."""

    robot: MobileManipulator
    params: PinvParams = field(default_factory=PinvParams)

    def set_params(self, params: PinvParams) -> None:
        self.params = params

    def reset(self) -> None:
        """Stateless: nothing to forget."""

    def step(
        self, q: Array, task: Task, dt: float, obstacles: Sequence[Circle] = ()
    ) -> LawOutput:
        """One step; ``dt`` and ``obstacles`` are accepted for a common signature and unused."""
        start = time.perf_counter()
        q = require_finite("configuration q", q)
        pose, jacobian = self.robot.kinematics(q)
        error, task_jacobian = task.error(pose, jacobian, q)
        u = pinv_velocity(task_jacobian, error, self.params.eta)
        return summarise(u, "optimal", None, (), error, start)
