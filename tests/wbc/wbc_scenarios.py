"""The robot, tasks from the configurations of ``wbc.geometry.scenarios``, a kinematic integrator,
random configurations, a step's context, central differences and DQ Robotics' chain: shared by
the tests of ``wbc``."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from dqrobotics import DQ
from dqrobotics.robot_modeling import DQ_HolonomicBase, DQ_SerialManipulatorDH, DQ_WholeBody

from profiles.deploy_files import ROBOT_FILE
from wbc import dq
from wbc.geometry.obstacles3d import Solid
from wbc.geometry.scenarios import DT
from wbc.laws import kinematic_run
from wbc.laws.kinematic_run import Run
from wbc.laws.step_context import StepContext
from wbc.robot import MobileManipulator
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


def configurations(
    model: MobileManipulator,
    count: int,
    seed: int,
    low: Sequence[float] = (-2.0, -2.0, -np.pi),
    high: Sequence[float] = (2.0, 2.0, np.pi),
) -> np.ndarray:
    """``count`` configurations: the base uniform between ``low`` and ``high`` (x, y, phi;
    by default anywhere in a 4 m square, facing anywhere), the arm over its joint box."""
    rng = np.random.default_rng(seed)
    base = rng.uniform(low, high, (count, 3))
    arm = rng.uniform(model.q_min[3:], model.q_max[3:], (count, model.arm_dof))
    return np.hstack((base, arm))


def context(
    model: MobileManipulator,
    q: np.ndarray,
    solids: tuple[Solid, ...] = (),
    previous_u: np.ndarray | None = None,
) -> StepContext:
    """A step's context at q with no error, goal or circle: what the terms and the rows that
    read q, the solids and u_prev see."""
    return StepContext(
        model, q, np.zeros(8), np.zeros(8), np.zeros(2), (), None, DT, solids, previous_u=previous_u
    )


def central_difference(
    function: Callable[[np.ndarray], np.ndarray | float], q: np.ndarray, step: float = 1e-6
) -> np.ndarray:
    """The derivative of ``function`` at q by central differences, one column per entry."""
    columns = []
    for i in range(q.size):
        offset = np.zeros_like(q)
        offset[i] = step
        columns.append(
            (np.asarray(function(q + offset)) - np.asarray(function(q - offset))) / (2.0 * step)
        )
    return np.stack(columns, axis=-1)


def oracle_chain(model: MobileManipulator, frame: int) -> DQ_WholeBody:
    """DQ Robotics' whole body up to DH frame ``frame`` (>= 1): the base, its height and the
    first ``frame`` links."""
    base = DQ_HolonomicBase()
    base.set_frame_displacement(DQ(dq.pose(dq.ONE[:4], [0.0, 0.0, model.base_height])))
    body = DQ_WholeBody(base)
    body.add(DQ_SerialManipulatorDH(np.array(model.dh)[:, :frame]))
    return body
