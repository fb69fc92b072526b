"""The kinematic runs of chapter 6's set-ups (q += u dt at 50 Hz from ``HOME``), each law by
its label (``parsimony.reproduce.laws``) and with the words of what it ran."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from parsimony.benchmark import UNBOUNDED_SPEED
from parsimony.kinematic_demo import BORDER_PARAMS, LP_PARAMS, input_change_gains
from parsimony.reproduce import laws as L
from wbc import dq
from wbc.cascade_law import CascadeLaw, CascadeParams
from wbc.kinematic_run import Run, integrate
from wbc.law_output import Law
from wbc.lp_law import LPLaw
from wbc.obstacles import Obstacle
from wbc.pinv_law import PinvParams, PseudoinverseLaw
from wbc.qp_law import QPLaw, QPParams
from wbc.robot import MobileManipulator
from wbc.scenarios import DT, HOME, JOINT_LIMIT_GOAL, OBSTACLE, OBSTACLE_GOAL, REACH_GOAL
from wbc.task import PoseTask, PositionTask, Task

STEPS = 4000
"""80 s of 50 Hz steps: the longest run."""


@dataclass(frozen=True)
class Experiment:
    """A set-up of chapter 6: its task, the runs of its laws and what each law ran."""

    name: str
    task: Task
    eta: float
    runs: dict[str, Run]
    laws: dict[str, str]
    obstacles: tuple[Obstacle, ...] = ()


def run_laws(name: str, task: Task, eta: float, laws: dict[str, Law],
             obstacles: tuple[Obstacle, ...] = ()) -> Experiment:  # fmt: skip
    runs = {label: integrate(law, HOME, task, DT, STEPS, obstacles=obstacles)
            for label, law in laws.items()}  # fmt: skip
    return Experiment(name, task, eta, runs,
                      {label: L.describe(law, obstacles) for label, law in laws.items()},
                      obstacles)  # fmt: skip


def experiments(robot: MobileManipulator) -> dict[str, Experiment]:
    """6.2.1 (pose), 6.2.2 (position), the joint limit of figure 6.10 and 6.2.3 (obstacle),
    each with its laws: the default LP, 5.29 as written and the cascade as the dissertation ran
    it and held to the robot's bounds; for table 6.1, the cascade with the eta that converges
    in the LP's time and the LP without its speed bounds beside the pseudoinverse under 5.11;
    for future work 1 and 5 of 7.2, the LP with its input change term and the QP."""
    free = robot.with_velocity_max(np.full(robot.dof, UNBOUNDED_SPEED))
    reach = robot.fkm(REACH_GOAL)
    tasks = {"pose": PoseTask(reach), "position": PositionTask(dq.translation(reach)[1:])}
    found = {}
    for name, task in tasks.items():
        params = LP_PARAMS[name]
        found[name] = run_laws(name, task, params.eta, {
            L.LP: LPLaw(robot, params),
            L.LP_5_29: LPLaw(robot, L.bare_5_29(params)),
            L.CASCADE: CascadeLaw(robot, CascadeParams(eta=params.eta)),
            L.SATURATED: CascadeLaw(robot, CascadeParams(eta=params.eta, saturate=True)),
            L.LP_FREE: LPLaw(free, params),
            L.PINV_5_11: PseudoinverseLaw(robot, PinvParams(eta=params.eta, nonholonomic=True)),
            L.QP: QPLaw(robot, QPParams(eta=params.eta, beta=params.beta)),
            L.LP_INPUT_CHANGE: LPLaw(robot, replace(params, **input_change_gains())),
        })  # fmt: skip
        eta = matched_eta(robot, task, len(found[name].runs[L.LP].outputs))
        matched = CascadeLaw(robot, CascadeParams(eta=eta))
        found[name].runs[L.CASCADE_LP_TIME] = integrate(matched, HOME, task, DT, STEPS)
        found[name].laws[L.CASCADE_LP_TIME] = L.describe(matched)
    pose = LP_PARAMS["pose"]
    found["joint_limit"] = run_laws("joint_limit", PoseTask(robot.fkm(JOINT_LIMIT_GOAL)), pose.eta,
                                    {L.LP: LPLaw(robot, pose),
                                     L.LP_5_29: LPLaw(robot, L.bare_5_29(pose)),
                                     L.CASCADE: CascadeLaw(robot, CascadeParams(eta=pose.eta)),
                                     L.SATURATED: CascadeLaw(robot, CascadeParams(
                                         eta=pose.eta, saturate=True))})  # fmt: skip
    found["obstacle"] = run_laws("obstacle", PoseTask(robot.fkm(OBSTACLE_GOAL)), pose.eta, {
        L.LP: LPLaw(robot, LP_PARAMS["obstacle"]), L.LP_BORDER: LPLaw(robot, BORDER_PARAMS),
        L.LP_5_29: LPLaw(robot, L.bare_5_29(pose))}, (OBSTACLE,))  # fmt: skip
    return found


def matched_eta(robot: MobileManipulator, task: Task, steps: int) -> float:
    """The cascade's eta that converges in ``steps`` (bisection on eta in [0.3, 3], to 1 %):
    the dissertation tuned both laws "for a fast and smooth convergence"."""
    low, high = 0.3, 3.0
    while high / low > 1.01:
        eta = math.sqrt(low * high)
        taken = len(integrate(CascadeLaw(robot, CascadeParams(eta=eta)), HOME, task, DT,
                              STEPS).outputs)  # fmt: skip
        low, high = (eta, high) if taken > steps else (low, eta)
    return math.sqrt(low * high)
