"""The staging legs' tasks follow the robot: their rows are the base's and one per joint of
the arm configuration given, their Jacobians the derivatives of their errors (checked by
finite differences on a 7-joint and a 12-joint arm), and a configuration of another size than
q's is refused; the staging search moves every joint but the waist."""

from __future__ import annotations

import numpy as np
import pytest

from profiles.deploy_files import ROBOTS_DIR
from wbc.planning.drive_tasks import HeadingTask, PointTask
from wbc.planning.whole_body_ik import free_entries
from wbc.robot import MobileManipulator


def numeric_jacobian(task, q: np.ndarray, step: float = 1e-7) -> np.ndarray:
    columns = []
    for i in range(q.size):
        dq = np.zeros(q.size)
        dq[i] = step
        plus, _ = task.error(None, None, q + dq)
        minus, _ = task.error(None, None, q - dq)
        columns.append((plus - minus) / (2 * step))
    return np.column_stack(columns)


@pytest.mark.parametrize("name", ["arm7_differential", "snake12"])
def test_the_legs_tasks_have_a_row_per_joint(name: str) -> None:
    robot = MobileManipulator.from_yaml(ROBOTS_DIR / f"{name}.yaml")
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.5, 0.5, robot.dof)
    arm = rng.uniform(-0.5, 0.5, robot.arm_dof)
    for task, rows in [
        (PointTask(np.array([1.0, 0.5]), arm, 0.1), 2 + robot.arm_dof),
        (HeadingTask(0.3, arm, np.array([1.0, 0.5])), 1 + robot.arm_dof),
    ]:
        error, jacobian = task.error(None, None, q)
        assert task.dof == rows and error.shape == (rows,)
        assert jacobian.shape == (rows, robot.dof)
        np.testing.assert_allclose(jacobian, numeric_jacobian(task, q), atol=1e-6)


def test_an_arm_configuration_of_another_size_than_q_is_refused() -> None:
    task = PointTask(np.array([1.0, 0.5]), np.zeros(7))
    with pytest.raises(ValueError, match="q has 8 entries, the task's arm 7 joints"):
        task.error(None, None, np.zeros(8))
    with pytest.raises(ValueError, match="arm configuration"):
        HeadingTask(0.0, np.zeros(0), np.zeros(2))


def test_the_staging_search_moves_the_base_and_every_joint_but_the_waist() -> None:
    assert free_entries(8) == [0, 1, 2, 4, 5, 6, 7]  # Little John's
    assert free_entries(15) == [0, 1, 2, *range(4, 15)]
