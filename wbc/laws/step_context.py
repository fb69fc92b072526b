"""What a constraint or an objective term of the LP (5.29) sees at one control step."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from wbc.geometry.obstacles import Circle
from wbc.geometry.obstacles3d import Solid
from wbc.robot import Chain, MobileManipulator

Array = np.ndarray


class StepContext(NamedTuple):
    """The state of one control step: configuration, task error and its rate, goal, obstacles,
    and the u the law gave at its previous step. Read-only; a named tuple, built at every
    step in a third of the time of a frozen dataclass of its eleven fields."""

    robot: MobileManipulator
    q: Array
    error: Array
    error_rate: Array
    goal_xy: Array
    """The goal's end-effector position projected on the floor (q_d of 5.25)."""
    obstacles: tuple[Circle, ...] = ()
    """The circles the base keeps clear of."""
    goal_pose: Array | None = None
    """The goal's end-effector pose for a pose task; None for a position task."""
    dt: float = 0.0
    """The step's period, s (0 where no step is taken, as in a test of one term)."""
    solids: tuple[Solid, ...] = ()
    """The obstacles in 3-D the robot's collision parts keep clear of (wbc.geometry.obstacles3d)."""
    previous_u: Array | None = None
    """The u the law returned at its previous step (u_prev), read-only: zero before a law's
    first step; None where no law steps (a term tested alone)."""
    chain: Chain | None = None
    """The forward kinematics at q (``MobileManipulator.forward``), shared by the task and the
    rows that need every frame; None where a context is built by hand (they then compute it)."""
