"""A step's context built by hand for the LP constraints' tests (wbc/laws/constraints/): the
robot, a base pose, and hypothesis' strategies they share."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import settings
from hypothesis import strategies as st

from profiles.deploy_files import ROBOT_FILE
from wbc.geometry.obstacles import Circle
from wbc.laws.step_context import StepContext
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
NO_DEADLINE = settings(deadline=None)
finite = st.floats(-5.0, 5.0)
angles = st.floats(-math.pi, math.pi)


def context(
    q: np.ndarray | None = None,
    error: np.ndarray | None = None,
    error_rate: np.ndarray | None = None,
    goal_xy: tuple[float, float] = (0.0, 0.0),
    obstacles: tuple[Circle, ...] = (),
) -> StepContext:
    return StepContext(
        robot=ROBOT,
        q=np.zeros(ROBOT.dof) if q is None else np.asarray(q, float),
        error=np.zeros(8) if error is None else np.asarray(error, float),
        error_rate=np.zeros(8) if error_rate is None else np.asarray(error_rate, float),
        goal_xy=np.asarray(goal_xy, float),
        obstacles=obstacles,
    )


def base_at(x: float, y: float, phi: float = 0.0) -> np.ndarray:
    return np.array([x, y, phi, 0.0, 0.0, 0.0, 0.0, 0.0])
