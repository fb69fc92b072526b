"""The obstacle circulation (wbc/laws/objectives/obstacle_circulation.py): round an obstacle
once the base stalls on its border."""

from __future__ import annotations

import numpy as np

from tests.wbc.laws.objectives.objective_steps import MODEL
from wbc.geometry.obstacles import Circle
from wbc.geometry.scenarios import HOME
from wbc.laws.objectives.obstacle_circulation import ObstacleCirculation
from wbc.laws.step_context import StepContext


def test_obstacle_circulation_acts_only_after_the_base_stalls_on_an_engaged_border():
    obstacle = Circle(0.45, 0.0, 0.1)
    term = ObstacleCirculation(
        weight=0.2, speed=0.1, margin=0.05, lookahead=0.1, stall_speed=0.01, stall_time=0.1
    )
    q = HOME.copy()  # the point 0.1 ahead lies 0.35 from the centre: inside the border

    def step(at: np.ndarray):
        ctx = StepContext(
            MODEL, at, np.ones(8), -np.ones(8), np.array([1.5, 0.0]), (obstacle,), None, 0.02
        )
        return term.cost(ctx)

    moving = [step(q + np.array([0.01 * k, 0, 0, 0, 0, 0, 0, 0])) for k in range(10)]
    assert all(cost.weight == 0.0 for cost in moving)  # 0.5 m/s along the way: no stall
    standing = [step(q + np.array([0.09, 0, 0, 0, 0, 0, 0, 0])) for _ in range(10)]
    assert standing[3].weight == 0.0 and standing[-1].weight == 0.2
    tangent = standing[-1].matrix[0, :2]
    assert abs(tangent @ np.array([1.0, 0.0])) < 1e-12  # along the border, not into it
    far = step(np.concatenate(([2.0, 0.0], HOME[2:])))  # past the obstacle: released
    assert far.weight == 0.0
