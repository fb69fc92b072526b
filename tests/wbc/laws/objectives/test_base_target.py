"""The base target (wbc/laws/objectives/base_target.py): the base steered to a point behind the
goal, along the gripper's heading."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.wbc.laws.objectives.objective_steps import MODEL, context
from wbc import dq
from wbc.geometry.scenarios import DT, HOME
from wbc.laws.lp_law import LPLaw
from wbc.laws.objectives.base_target import BaseTarget, gripper_heading
from wbc.task import PositionTask


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


@pytest.mark.parametrize(
    "make",
    [
        lambda: BaseTarget(0.05, 2.0, -0.1, 0.15),
        lambda: BaseTarget(0.05, 2.0, 0.36, 0.0),
        lambda: BaseTarget(0.05, 2.0, 0.36, 0.15, on=0.1, off=0.2),
    ],
)
def test_invalid_base_target_gains_are_refused(make):
    with pytest.raises(ValueError):
        make()
