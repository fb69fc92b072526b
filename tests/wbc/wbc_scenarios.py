"""Start configurations and goals shared by the closed-loop tests, and a kinematic integrator.

The goals are end-effector poses and positions of configurations some 0.4 to 0.9 m ahead of
the robot, as in the pick-and-place experiments of section 6.2.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from wbc import dq, kinematic_run
from wbc.kinematic_run import Run
from wbc.robot import MobileManipulator
from wbc.task import PoseTask, PositionTask

ROBOT_FILE = Path(__file__).resolve().parents[2] / "deploy" / "robots" / "little_john.yaml"
HOME = np.array([0.0, 0.0, 0.0, 0.0, -0.2, 0.2, 0.0, 0.5])
DT = 0.02

STARTS_AND_GOALS = [
    (
        np.array([-0.15, 0.0, 0.04, -0.28, -0.41, 0.3, -0.26, 0.28]),
        np.array([0.87, 0.07, -0.08, 0.01, -0.07, -0.5, -0.36, 0.46]),
    ),
    (
        np.array([0.07, 0.0, 0.13, 0.03, 0.09, 0.02, 0.03, 0.49]),
        np.array([0.58, 0.05, -0.16, 0.3, 0.15, -0.66, -0.03, -0.36]),
    ),
    (
        np.array([0.1, -0.12, -0.18, 0.06, 0.04, -0.08, 0.18, 0.31]),
        np.array([0.45, -0.29, -0.12, 0.23, -0.26, 0.14, -0.28, -0.3]),
    ),
]


def robot() -> MobileManipulator:
    return MobileManipulator.from_yaml(ROBOT_FILE)


def pose_task(model: MobileManipulator, q_goal: np.ndarray) -> PoseTask:
    return PoseTask(model.fkm(q_goal))


def position_task(model: MobileManipulator, q_goal: np.ndarray) -> PositionTask:
    return PositionTask(dq.translation(model.fkm(q_goal))[1:])


def integrate(law, q0, task, steps: int, tolerance: float = 1e-3, obstacles=()) -> Run:
    """Integrate at the dissertation's 50 Hz (section 6.3)."""
    return kinematic_run.integrate(law, q0, task, DT, steps, tolerance, obstacles)
