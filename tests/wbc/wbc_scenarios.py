"""The robot, tasks from the configurations of ``wbc.scenarios``, and a kinematic integrator,
shared by the closed-loop tests."""

from __future__ import annotations

import numpy as np

from deploy import ROBOT_FILE
from wbc import dq, kinematic_run
from wbc.kinematic_run import Run
from wbc.robot import MobileManipulator
from wbc.scenarios import DT
from wbc.task import PoseTask, PositionTask


def robot() -> MobileManipulator:
    return MobileManipulator.from_yaml(ROBOT_FILE)


def pose_task(model: MobileManipulator, q_goal: np.ndarray) -> PoseTask:
    return PoseTask(model.fkm(q_goal))


def position_task(model: MobileManipulator, q_goal: np.ndarray) -> PositionTask:
    return PositionTask(dq.translation(model.fkm(q_goal))[1:])


def integrate(law, q0, task, steps: int, tolerance: float = 1e-3, obstacles=()) -> Run:
    """Integrate at the dissertation's 50 Hz (section 6.3)."""
    return kinematic_run.integrate(law, q0, task, DT, steps, tolerance, obstacles)
