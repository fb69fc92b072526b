"""Closed-loop kinematic runs, q_{k+1} = q_k + u_k dt, and the control effort of table 6.1."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from wbc.geometry.obstacles import Obstacle
from wbc.laws.law_output import Law, LawOutput
from wbc.task import Task

Array = np.ndarray


@dataclass
class Run:
    """Configurations before each step, and each step's output."""

    dt: float
    tolerance: float = 1e-3
    configurations: list[Array] = field(default_factory=list)
    outputs: list[LawOutput] = field(default_factory=list)
    reached: bool | None = None
    """Set by a supervised run: its supervisor's verdict (the last task may not be the goal's)."""

    @property
    def final_error(self) -> float:
        return self.outputs[-1].error_norm

    @property
    def converged(self) -> bool:
        if self.reached is not None:
            return self.reached
        return bool(self.outputs) and self.outputs[-1].error_norm < self.tolerance

    def velocities(self) -> Array:
        return np.array([out.u for out in self.outputs])


def integrate(
    law: Law,
    q0: Array,
    task: Task,
    dt: float,
    steps: int,
    tolerance: float = 1e-3,
    obstacles: Sequence[Obstacle] = (),
) -> Run:
    """Step ``law`` and integrate q += u dt until ||e|| < ``tolerance`` or ``steps`` run out."""
    run = Run(dt=dt, tolerance=tolerance)
    q = np.array(q0, dtype=float)
    for _ in range(steps):
        out = law.step(q, task, dt, obstacles)
        run.configurations.append(q.copy())
        run.outputs.append(out)
        if out.error_norm < tolerance:
            break
        q = q + out.u * dt
    return run


class Supervisor(Protocol):
    """What hands a law its task step by step (wbc.planning.staging_supervisor)."""

    @property
    def reached(self) -> bool: ...

    def step(self, q: Array, t: float) -> Task | None: ...


def integrate_supervised(
    law: Law,
    supervisor: Supervisor,
    q0: Array,
    dt: float,
    steps: int,
    obstacles: Sequence[Obstacle] = (),
) -> Run:
    """As ``integrate``, with the task of each step from ``supervisor``, until it reports the
    goal reached, gives no task (the robot stops) or ``steps`` run out. The law is reset
    whenever the task changes."""
    run = Run(dt=dt)
    q = np.array(q0, dtype=float)
    task = None
    for k in range(steps):
        current = supervisor.step(q, k * dt)
        if current is None:
            break
        if current is not task:
            law.reset()
            task = current
        out = law.step(q, task, dt, obstacles)
        run.configurations.append(q.copy())
        run.outputs.append(out)
        if supervisor.reached:
            break
        q = q + out.u * dt
    run.reached = supervisor.reached
    return run


@dataclass(frozen=True)
class ControlEffort:
    """The four metrics of table 6.1, integrals over the run by the rectangle rule."""

    velocity_l1: float
    """int ||q'||_1 dt"""
    velocity_l2: float
    """sqrt(int ||q'||_2^2 dt)"""
    acceleration_l1: float
    """int ||q''||_1 dt, with q'' the finite difference of q'"""
    acceleration_l2: float
    """sqrt(int ||q''||_2^2 dt)"""


def control_effort(run: Run, from_rest: bool = False) -> ControlEffort:
    """Table 6.1's metrics of a run's velocities; ``from_rest``, with u = 0 before the first
    step (the robot stood still before its first command, so the jump to it counts, as it does
    in a recorded run, where the commands before the goal are zero)."""
    velocities = run.velocities()
    if from_rest and len(velocities):
        velocities = np.vstack((np.zeros_like(velocities[:1]), velocities))
    return effort_of(velocities, run.dt)


def effort_of(velocity: Array, dt: float) -> ControlEffort:
    """Table 6.1's metrics of velocities u (one row per step, ``dt`` apart)."""
    acceleration = np.diff(velocity, axis=0) / dt
    return ControlEffort(
        velocity_l1=float(np.abs(velocity).sum() * dt),
        velocity_l2=float(np.sqrt((velocity**2).sum() * dt)),
        acceleration_l1=float(np.abs(acceleration).sum() * dt),
        acceleration_l2=float(np.sqrt((acceleration**2).sum() * dt)),
    )
