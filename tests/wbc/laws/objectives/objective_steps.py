"""A step's context for the LP's secondary objective terms' tests (wbc/laws/objectives/): the
robot, the waist's and the base yaw's entries of u, and a context at q with an error and an
optional goal pose."""

from __future__ import annotations

import numpy as np

from tests.wbc.wbc_scenarios import robot
from wbc.laws.step_context import StepContext

MODEL = robot()
WAIST, YAW = 3, 2


def context(q: np.ndarray, goal_pose: np.ndarray | None, error: np.ndarray) -> StepContext:
    return StepContext(MODEL, q, error, -error, np.zeros(2), (), goal_pose)
