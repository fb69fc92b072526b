"""The kinematic runs of chapter 6's set-ups (q += u dt at 50 Hz from ``HOME``), each law by
its label (``studies.reproduce.laws``) and with the words of what it ran."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from studies.gain_sets import BORDER_PARAMS, LP_PARAMS, bare_5_29, input_change_gains
from studies.reproduce import laws as L
from wbc import dq
from wbc.geometry.obstacles import Obstacle
from wbc.geometry.scenarios import DT, HOME, JOINT_LIMIT_GOAL, OBSTACLE, OBSTACLE_GOAL, REACH_GOAL
from wbc.laws.cascade_law import CascadeLaw, CascadeParams
from wbc.laws.kinematic_run import Run, integrate
from wbc.laws.law_output import Law
from wbc.laws.lp_law import LPLaw
from wbc.laws.pinv_law import PinvParams, PseudoinverseLaw
from wbc.laws.qp_law import QPLaw, QPParams
from wbc.robot import MobileManipulator
from wbc.task import PoseTask, PositionTask, Task

STEPS = 4000
"""80 s of 50 Hz steps: the longest run."""


NAMES = ("pose", "position", "joint_limit", "obstacle")
"""The set-ups: 6.2.1 (pose), 6.2.2 (position), the joint limit of figure 6.10, 6.2.3."""


@dataclass(frozen=True)
class Experiment:
    """A set-up of chapter 6: its task, the runs of its laws and what each law ran. A run on
    the whole loop (``studies.reproduce.loop``) gives the task of each of its steps (the goal
    the controller held) and its true configurations, where they are not the run's own."""

    name: str
    task: Task
    eta: float
    runs: dict[str, Run]
    laws: dict[str, str]
    obstacles: tuple[Obstacle, ...] = ()
    tasks: Mapping[str, list[Task]] = field(default_factory=dict)
    """The task of each step of a run, by label; ``task`` at every step of the others."""
    truth: Mapping[str, Run] = field(default_factory=dict)
    """A run's true configurations (the simulator's world) beside its outputs, by label."""
    until: str = "||e|| < 1e-3"
    """Where a run stops."""

    def step_tasks(self, label: str) -> Task | list[Task]:
        """The task of each step of run ``label``, or the one task of them all."""
        return self.tasks.get(label, self.task)

    def true_run(self, label: str) -> Run:
        """Run ``label`` with its true configurations."""
        return self.truth.get(label, self.runs[label])


def run_laws(
    name: str, task: Task, eta: float, laws: dict[str, Law], obstacles: tuple[Obstacle, ...] = ()
) -> Experiment:
    runs = {
        label: integrate(law, HOME, task, DT, STEPS, obstacles=obstacles)
        for label, law in laws.items()
    }
    return Experiment(
        name,
        task,
        eta,
        runs,
        {label: L.describe(law, obstacles) for label, law in laws.items()},
        obstacles,
    )


def task_of(robot: MobileManipulator, name: str) -> Task:
    """The task of set-up ``name`` (one of ``NAMES``)."""
    reach = robot.fkm(REACH_GOAL)
    return {
        "pose": PoseTask(reach),
        "position": PositionTask(dq.translation(reach)[1:]),
        "joint_limit": PoseTask(robot.fkm(JOINT_LIMIT_GOAL)),
        "obstacle": PoseTask(robot.fkm(OBSTACLE_GOAL)),
    }[name]


def laws_of(robot: MobileManipulator, name: str) -> dict[str, Law]:
    """The laws of set-up ``name`` by label: the default LP, 5.29 as written and the cascade as
    the dissertation ran it and held to the robot's bounds; on the pose and the position task,
    for table 6.1, the LP without its speed bounds beside the pseudoinverse under 5.11, and for
    future work 1 and 5 of 7.2, the LP with its input change term and the QP. On the obstacle
    task, the default LP, the LP with 5.28 in place of the vector-field inequality and 5.29 as
    written (no cascade: appendix B has no obstacle row)."""
    pose = LP_PARAMS["pose"]
    if name == "obstacle":
        return {
            L.LP: LPLaw(robot, LP_PARAMS["obstacle"]),
            L.LP_BORDER: LPLaw(robot, BORDER_PARAMS),
            L.LP_5_29: LPLaw(robot, bare_5_29(pose)),
        }
    params = pose if name == "joint_limit" else LP_PARAMS[name]
    laws: dict[str, Law] = {
        L.LP: LPLaw(robot, params),
        L.LP_5_29: LPLaw(robot, bare_5_29(params)),
        L.CASCADE: CascadeLaw(robot, CascadeParams(eta=params.eta)),
        L.SATURATED: CascadeLaw(robot, CascadeParams(eta=params.eta, saturate=True)),
    }
    if name == "joint_limit":
        return laws
    free = robot.with_velocity_max(np.full(robot.dof, L.UNBOUNDED_SPEED))
    return laws | {
        L.LP_FREE: LPLaw(free, params),
        L.PINV_5_11: PseudoinverseLaw(robot, PinvParams(eta=params.eta, nonholonomic=True)),
        L.QP: QPLaw(robot, QPParams(eta=params.eta, beta=params.beta)),
        L.LP_INPUT_CHANGE: LPLaw(robot, replace(params, **input_change_gains())),
    }


def experiments(robot: MobileManipulator, names: tuple[str, ...] = NAMES) -> dict[str, Experiment]:
    """The set-ups ``names``, each with the runs of its laws (``laws_of``); on the pose and the
    position task, for table 6.1, also the cascade with the eta that converges in the LP's
    time."""
    found = {}
    for name in NAMES:
        if name not in names:
            continue
        eta = LP_PARAMS[name].eta if name in ("pose", "position") else LP_PARAMS["pose"].eta
        task = task_of(robot, name)
        found[name] = run_laws(
            name, task, eta, laws_of(robot, name), (OBSTACLE,) if name == "obstacle" else ()
        )
        if name in ("pose", "position"):
            matched = CascadeLaw(
                robot,
                CascadeParams(eta=matched_eta(robot, task, len(found[name].runs[L.LP].outputs))),
            )
            found[name].runs[L.CASCADE_LP_TIME] = integrate(matched, HOME, task, DT, STEPS)
            found[name].laws[L.CASCADE_LP_TIME] = L.describe(matched)
    return found


def matched_eta(robot: MobileManipulator, task: Task, steps: int) -> float:
    """The cascade's eta that converges in ``steps`` (bisection on eta in [0.3, 3], to 1 %):
    the dissertation tuned both laws "for a fast and smooth convergence"."""
    low, high = 0.3, 3.0
    while high / low > 1.01:
        eta = math.sqrt(low * high)
        taken = len(
            integrate(CascadeLaw(robot, CascadeParams(eta=eta)), HOME, task, DT, STEPS).outputs
        )
        low, high = (eta, high) if taken > steps else (low, eta)
    return math.sqrt(low * high)
