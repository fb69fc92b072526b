"""The secondary objective terms of the LP (wbc/laws/objectives/), alone and inside the law."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.wbc.wbc_scenarios import robot
from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.geometry.scenarios import DT, HOME
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.objectives.base_target import BaseTarget, gripper_heading
from wbc.laws.objectives.obstacle_circulation import ObstacleCirculation
from wbc.laws.objectives.velocity_cost import LeastVelocity
from wbc.laws.objectives.waist_centring import WaistCentring
from wbc.laws.objectives.waist_hold import WaistHold
from wbc.laws.step_context import StepContext
from wbc.task import PoseTask, PositionTask

MODEL = robot()
WAIST, YAW = 3, 2


def context(q: np.ndarray, goal_pose: np.ndarray | None, error: np.ndarray) -> StepContext:
    return StepContext(MODEL, q, error, -error, np.zeros(2), (), goal_pose)


def test_the_waist_hold_gives_the_tasks_yaw_to_the_base_at_no_cost_in_entries():
    """phi' and q1' are never both nonzero (the split would be an eighth entry), and the waist
    stays where it is."""
    task = PoseTask(MODEL.fkm(np.concatenate(([0.3, 0.1, 0.2, 0.3], HOME[4:]))))
    start = HOME.copy()
    start[WAIST] = 0.2
    law = LPLaw(MODEL)
    for _ in range(50):
        out = law.step(start, task, DT)
        assert not (abs(out.u[YAW]) > 1e-9 and abs(out.u[WAIST]) > 1e-9), out.u
        assert out.nonzero <= 7
        start = start + DT * out.u
    assert start[WAIST] == pytest.approx(0.2)


def test_waist_centring_asks_for_q1_rate_minus_k_q1_and_fades_near_the_goal():
    q = HOME.copy()
    q[WAIST] = 0.4
    term = WaistCentring(weight=0.02, gain=1.5, fade_error=0.05)
    far = term.cost(context(q, None, np.full(8, 0.1)))
    u = np.zeros(MODEL.dof)
    u[WAIST] = -1.5 * 0.4
    assert far.weight == pytest.approx(0.02)
    assert abs((far.matrix @ u + far.offset)[0]) < 1e-12
    near = term.cost(context(q, None, np.full(8, 0.1 / 32)))  # ||e||_1 = 0.025
    assert near.weight == pytest.approx(0.01)


def test_the_law_spends_the_self_motion_on_centring_the_waist():
    """With the waist turned, the LP turns the base and the waist against each other
    (phi' = -q1' moves no part of the end effector, 4.9): q1 heads back to 0 at no cost to
    the task residual ||J u + eta e||_1. (The term is off by default.)"""
    goal = HOME.copy()
    start = goal.copy()
    start[YAW], start[WAIST] = -0.3, 0.3  # the same end-effector pose as the goal's
    np.testing.assert_allclose(MODEL.fkm(start), MODEL.fkm(goal), atol=1e-12)
    task = PoseTask(MODEL.fkm(np.concatenate(([0.02], goal[1:]))))  # 2 cm ahead
    pose, jacobian = MODEL.kinematics(start)
    error, _ = task.error(pose, jacobian)

    def residual(params: LPParams) -> tuple[np.ndarray, float]:
        u = LPLaw(MODEL, params).step(start, task, DT).u
        return u, float(np.abs(jacobian @ u + params.eta * error).sum())

    centring = {"base_target": 0.0, "waist_hold": 0.0}
    centred, centred_residual = residual(LPParams(waist_centring=0.02, **centring))
    _, plain_residual = residual(LPParams(waist_centring=0.0, **centring))
    assert centred[WAIST] < 0.0 < centred[YAW]
    assert centred_residual == pytest.approx(plain_residual, abs=1e-9)


@pytest.mark.parametrize("phi, q1", [(0.0, 0.0), (0.5, -0.3), (-2.0, 1.2), (3.0, 0.4)])
def test_with_the_wrist_at_zero_the_gripper_heads_along_the_arm_plane(phi, q1):
    q = np.array([0.3, -0.2, phi, q1, -0.4, 0.1, 0.0, 0.0])
    psi = gripper_heading(MODEL.fkm(q))
    assert math.cos(psi - phi - q1) == pytest.approx(1.0, abs=1e-12)


def test_base_target_lies_behind_the_goal_along_the_gripper_heading():
    goal = np.array([1.0, 0.5, 0.3, 0.2, -0.4, 0.1, 0.0, 0.0])
    pose = MODEL.fkm(goal)
    term = BaseTarget(weight=0.05, gain=2.0, reach=0.36, stop_distance=0.15)
    target_x, target_y = term.target(pose)
    end_effector = dq.translation(pose)[1:3]
    heading = 0.3 + 0.2
    np.testing.assert_allclose(
        end_effector - [target_x, target_y],
        0.36 * np.array([math.cos(heading), math.sin(heading)]),
        atol=1e-12,
    )


def test_base_target_sets_back_less_for_a_gripper_high_above_the_floor():
    goal = np.array([1.0, 0.5, 0.3, 0.2, -0.9, -1.0, 0.0, 0.0])  # the arm bent back, up
    pose = MODEL.fkm(goal)
    height = dq.translation(pose)[3]
    assert height > 0.6
    end_effector = dq.translation(pose)[1:3]
    heading = gripper_heading(pose)
    for shrink in (0.0, 1.0, 100.0):
        term = BaseTarget(0.05, 2.0, 0.36, 0.15, high=0.55, shrink=shrink)
        set_back = max(0.0, 0.36 - shrink * (height - 0.55))
        np.testing.assert_allclose(
            end_effector - term.target(pose),
            set_back * np.array([math.cos(heading), math.sin(heading)]),
            atol=1e-12,
        )


def test_base_target_ahead_only_never_turns_the_base_round_to_a_target_behind_it():
    goal = np.array([1.0, 0.0, 0.0, 0.0, -0.4, 0.1, 0.0, 0.6])
    pose = MODEL.fkm(goal)
    target_x, _ = BaseTarget(0.05, 4.0, 0.36, 0.15).target(pose)
    past = np.concatenate(([target_x + 0.5, 0.0, 0.0], HOME[3:]))  # the target 0.5 m behind
    turning = BaseTarget(0.05, 4.0, 0.36, 0.15)
    assert turning.cost(context(past, pose, np.ones(8))).weight == pytest.approx(0.05)
    ahead_only = BaseTarget(0.05, 4.0, 0.36, 0.15, ahead_only=True)
    assert ahead_only.cost(context(past, pose, np.ones(8))).weight == 0.0
    assert ahead_only.cost(context(HOME, pose, np.ones(8))).weight == pytest.approx(0.05)


def test_base_target_steers_in_bursts_from_its_on_heading_error_down_to_its_off():
    goal = np.array([1.0, 0.0, 0.0, 0.0, -0.4, 0.1, 0.0, 0.6])
    pose = MODEL.fkm(goal)
    term = BaseTarget(weight=0.05, gain=4.0, reach=0.36, stop_distance=0.15, on=0.3, off=0.05)
    target_x, target_y = term.target(pose)
    bearing = math.atan2(target_y, target_x)
    weights = []
    for phi in (bearing - 0.2, bearing - 0.4, bearing - 0.2, bearing - 0.01, bearing - 0.2):
        q = np.concatenate(([0.0, 0.0, phi], HOME[3:]))
        weights.append(term.cost(context(q, pose, np.ones(8))).weight)
    assert weights == [0.0, 0.05, 0.05, 0.0, 0.0]


def test_base_target_turns_towards_the_target_and_stops_near_it():
    goal = np.array([1.0, 1.0, 0.8, 0.0, -0.4, 0.1, 0.0, 0.6])
    pose = MODEL.fkm(goal)
    term = BaseTarget(weight=0.05, gain=2.0, reach=0.36, stop_distance=0.15)
    far = term.cost(context(HOME, pose, np.ones(8)))
    target_x, target_y = term.target(pose)
    bearing = math.atan2(target_y, target_x)  # the base is at the origin facing x
    assert far.weight == pytest.approx(0.05)
    assert -far.offset[0] == pytest.approx(2.0 * bearing)
    at_target = np.concatenate(([target_x, target_y], HOME[2:]))
    assert term.cost(context(at_target, pose, np.ones(8))).weight == 0.0


def test_base_target_is_idle_for_a_position_task():
    term = BaseTarget(weight=0.05, gain=2.0, reach=0.36, stop_distance=0.15)
    assert term.cost(context(HOME, None, np.ones(3))).weight == 0.0
    law = LPLaw(MODEL)
    out = law.step(HOME, PositionTask(np.array([1.0, 1.0, 0.3])), DT)
    assert out.ok


def test_least_velocity_weighs_every_entry_of_u():
    cost = LeastVelocity(1e-3).cost(context(HOME, None, np.ones(8)))
    np.testing.assert_array_equal(cost.weights, np.full(MODEL.dof, 1e-3))


@pytest.mark.parametrize(
    "make",
    [
        lambda: WaistCentring(-1.0, 1.0),
        lambda: WaistCentring(0.02, 0.0),
        lambda: BaseTarget(0.05, 2.0, -0.1, 0.15),
        lambda: BaseTarget(0.05, 2.0, 0.36, 0.0),
        lambda: LeastVelocity(float("nan")),
        lambda: WaistHold(-1e-3),
        lambda: BaseTarget(0.05, 2.0, 0.36, 0.15, on=0.1, off=0.2),
    ],
)
def test_invalid_term_parameters_are_refused(make):
    with pytest.raises(ValueError):
        make()


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
