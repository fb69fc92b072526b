"""Random states of Little John drawn by hypothesis: a configuration and a pose goal, the arm's
joints inside 80 % of their ranges."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from tests.wbc.wbc_scenarios import robot
from wbc.task import PoseTask

MODEL = robot()


def states(draw_q: np.ndarray, draw_goal: np.ndarray) -> tuple[np.ndarray, PoseTask]:
    """q and a pose task of the draws (each eight numbers in [0, 1]: ``unit``)."""
    low, high = 0.8 * MODEL.q_min[3:], 0.8 * MODEL.q_max[3:]
    q = np.concatenate((draw_q[:3], low + (high - low) * draw_q[3:]))
    goal = np.concatenate((draw_goal[:3], low + (high - low) * draw_goal[3:]))
    return q, PoseTask(MODEL.fkm(goal))


unit = st.lists(st.floats(0.0, 1.0), min_size=8, max_size=8).map(np.array)
"""Eight numbers in [0, 1]: a draw of ``states``."""
