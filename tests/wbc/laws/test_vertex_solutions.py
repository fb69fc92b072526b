"""Every optimal solution of the LP law is a vertex of 5.29, whatever the tie-break weight.

On random states (pose and position tasks, obstacles off and on, both error bounds, w = 0
and the default w) the builder is given the rows and costs the law gives it. At a vertex each
nonzero u_i is a basic column, so there are at most task DOF + secondary residual rows +
equality rows + active inequality rows of them (section 5.7 with 6.2.1; a secondary objective
term such as the waist centring is one more task row).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from tests.wbc.wbc_scenarios import robot
from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.laws.constraints.base import LinearRows, OneNormBound, VelocityBounds
from wbc.laws.law_output import ZERO_THRESHOLD
from wbc.laws.linear_program import WarmStartedLP
from wbc.laws.lp_law import LPParams, default_constraints, default_objectives, terms
from wbc.laws.objectives.base import ResidualCost
from wbc.laws.step_context import StepContext
from wbc.task import PoseTask, PositionTask

MODEL = robot()
STATES_PER_CASE = 25
CASES = list(
    itertools.product(
        (0.0, LPParams().velocity_cost),
        ("pose", "position"),
        (False, True),
        ("derivative", "error"),
    )
)


def random_step(rng: np.random.Generator, kind: str, obstacle: bool, params: LPParams):
    low = np.concatenate(([-1.0, -1.0, -np.pi], MODEL.q_min[3:]))
    high = np.concatenate(([1.0, 1.0, np.pi], MODEL.q_max[3:]))
    q = rng.uniform(low, high)
    goal = MODEL.fkm(q + rng.uniform(-0.5, 0.5, MODEL.dof))
    task = PoseTask(goal) if kind == "pose" else PositionTask(dq.translation(goal)[1:])
    pose, jacobian = MODEL.kinematics(q)
    error, task_jacobian = task.error(pose, jacobian)
    rate = -params.eta * error + rng.normal(0.0, 0.05, error.size)
    near = q[:2] + rng.uniform(-0.3, 0.3, 2)
    obstacles = (Circle(near[0], near[1], 0.1),) if obstacle else ()
    context = StepContext(MODEL, q, error, rate, task.goal_position[:2], obstacles)
    return task, task_jacobian, error, context


def vertex_bound(task_dof: int, costs: list, rows: list, active: tuple[str, ...]) -> int:
    """Task DOF + secondary residual rows + equality rows + velocity and one-norm bounds at
    their limit."""
    secondary = sum(cost.matrix.shape[0] for cost in costs[1:] if isinstance(cost, ResidualCost))
    equalities = sum(
        rows_.matrix.shape[0]
        for rows_ in rows
        if isinstance(rows_, LinearRows)
        and rows_.engaged
        and np.array_equal(rows_.lower, rows_.upper)
    )
    bound_names = {rows_.name for rows_ in rows if isinstance(rows_, VelocityBounds)}
    norm_names = {rows_.name for rows_ in rows if isinstance(rows_, OneNormBound)}
    active_inequalities = sum(
        1 for name in active if name.split("[")[0] in bound_names or name in norm_names
    )
    return task_dof + secondary + equalities + active_inequalities


@pytest.mark.parametrize(("weight", "kind", "obstacle", "bound"), CASES)
def test_optimal_solutions_are_vertices(weight, kind, obstacle, bound):
    rng = np.random.default_rng(CASES.index((weight, kind, obstacle, bound)))
    params = LPParams(
        velocity_cost=weight, error_bound=bound, obstacle_mode="border" if obstacle else "off"
    )
    constraints, objectives = default_constraints(params), default_objectives(params)
    lp = WarmStartedLP()
    solved = 0
    for index in range(STATES_PER_CASE):
        task, task_jacobian, error, context = random_step(rng, kind, obstacle, params)
        costs, rows = terms(context, task_jacobian, params.eta, constraints, objectives)
        if index % 2:
            lp.reset()  # half cold starts, half warm starts from an unrelated state
        solution = lp.solve(costs, rows)
        if solution.status != "optimal":
            continue
        solved += 1
        nonzero = int(np.count_nonzero(np.abs(solution.u) > ZERO_THRESHOLD))
        assert nonzero <= vertex_bound(task.dof, costs, rows, solution.active), solution
    assert solved >= STATES_PER_CASE // 2
