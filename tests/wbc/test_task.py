"""The tasks every law drives to zero (wbc/task.py): their goals checked and frozen, their
errors, and when two are one."""

from __future__ import annotations

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE
from wbc import dq
from wbc.geometry.scenarios import HOME, REACH_GOAL
from wbc.robot import MobileManipulator
from wbc.task import PoseTask, PositionTask, same_task

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)


def test_a_pose_task_has_one_error_for_both_signs_of_its_goal() -> None:
    goal = ROBOT.fkm(REACH_GOAL)
    pose, jacobian = ROBOT.kinematics(HOME)
    error, task_jacobian = PoseTask(goal).error(pose, jacobian)
    np.testing.assert_allclose(PoseTask(-goal).error(pose, jacobian)[0], error)
    assert task_jacobian is jacobian
    np.testing.assert_allclose(PoseTask(goal).goal_position, dq.translation(goal)[1:])
    np.testing.assert_allclose(
        PoseTask(goal).error(*ROBOT.kinematics(REACH_GOAL))[0], 0, atol=1e-12
    )


def test_a_position_task_error_is_the_position_less_the_goal_on_the_rows_of_j_p() -> None:
    pose, jacobian = ROBOT.kinematics(HOME)
    error, rows = PositionTask([1.0, 2.0, 3.0]).error(pose, jacobian)
    np.testing.assert_allclose(error, dq.translation(pose)[1:] - [1.0, 2.0, 3.0])
    assert rows.shape == (3, ROBOT.dof)


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: PoseTask(np.ones(8)), "unit dual quaternion"),
        (lambda: PoseTask(np.full(8, np.nan)), "goal pose"),
        (lambda: PositionTask([1.0, 2.0]), r"shape \(3,\)"),
        (lambda: PositionTask([1.0, np.inf, 0.0]), "goal position"),
    ],
)
def test_a_bad_goal_is_refused_naming_it(make, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        make()


def test_a_goal_cannot_change_under_its_task() -> None:
    given = np.array([1.0, 2.0, 3.0])
    task = PositionTask(given)
    given[0] = 9.0
    assert task.position[0] == 1.0
    with pytest.raises(ValueError):
        task.position[0] = 9.0


def test_same_task_compares_the_kind_and_the_goal_within_a_tolerance() -> None:
    a, b = PositionTask([1.0, 2.0, 3.0]), PositionTask([1.0, 2.01, 3.0])
    assert same_task(a, a) and not same_task(a, b) and same_task(a, b, tolerance=0.02)
    assert not same_task(a, PoseTask(ROBOT.fkm(HOME)), tolerance=10.0)
