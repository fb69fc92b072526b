"""The kinematic demo: the experiments of section 6.2 integrated as q += u dt, LP against cascade.

No simulator and no network: the laws of `wbc` on the robot model, at 50 Hz, printing for each
experiment whether it converged, in how many steps, how many joints it used and the control
effort of table 6.1.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from parsimony.output import table
from profiles.profile import load_profile
from wbc import dq
from wbc.cascade_law import CascadeLaw
from wbc.kinematic_run import Run, control_effort, integrate
from wbc.lp_law import LPLaw, LPParams
from wbc.obstacles import Circle
from wbc.pinv_law import PseudoinverseLaw
from wbc.robot import MobileManipulator
from wbc.scenarios import DT, HOME, JOINT_LIMIT_GOAL, OBSTACLE, OBSTACLE_GOAL, REACH_GOAL
from wbc.task import PoseTask, PositionTask, Task

ROBOT_FILE = Path(__file__).resolve().parents[1] / "deploy" / "robots" / "little_john.yaml"
STEPS = 4000
OBSTACLE_PARAMS = LPParams(base_target=0.0, waist_hold=0.0, waist_centring=0.02,
                           error_bound="error")
"""The obstacle experiment's law (6.2.3): the default obstacle constraint, the vector-field
inequality of wbc.constraints.obstacle_vector_field, in place of 5.28 (python -m
bench.obstacle_constraints compares them), the circulation term that takes the base round an
obstacle it stalled by, and no base target term, whose straight-line heading towards where the
base should stand fights the detour. The waist is centred through the self-motion instead of
held: with the base alone taking the task's yaw, the base overran the goal after its detour
(error 0.18 after 80 s); the self-motion costs an entry, and figure 6.17 shows all 8 in use too.
||u||_1 is bounded by the error (5.7), not by its rate (5.10): when the base stands still by
the obstacle, e' is 0, 5.10 allows no motion at all and the circulation could not start it
again (seed 1: error 0.65 after 60 s)."""

BORDER_PARAMS = replace(OBSTACLE_PARAMS, obstacle_mode="border")
"""The same law with the dissertation's border constraint 5.28, for comparison."""

SUPERVISED_PROFILE = Path(__file__).resolve().parents[1] / "deploy" / "sim_supervised.yaml"
"""The profile of the LP under the staging supervisor, which declares that LP's gains."""


@functools.cache
def supervised_params() -> LPParams:
    """The LP law's gains under the staging supervisor (wbc.staging_supervisor), as
    ``SUPERVISED_PROFILE`` gives its controller (declared there once, the reasons beside)."""
    controller = load_profile(SUPERVISED_PROFILE).component("controller")
    return LPParams(**{f.name: controller.params[f.name] for f in dataclasses.fields(LPParams)
                       if f.name in controller.params})  # fmt: skip


LP_PARAMS = {
    "pose": LPParams(eta=0.6, beta=15.0),
    "position": LPParams(eta=1.0, beta=10.0),
    "obstacle": OBSTACLE_PARAMS,
}
"""The LP law's gains in each experiment of section 6.2 (6.2.1 gives eta 0.6 and beta 15);
an experiment under the supervisor takes its profile's (``supervised_params``)."""


@dataclass(frozen=True)
class Experiment:
    name: str
    task: Task
    laws: dict[str, object]
    obstacles: tuple[Circle, ...] = ()


def experiments(robot: MobileManipulator) -> list[Experiment]:
    """Pose (6.2.1), position (6.2.2), obstacle (6.2.3) and the joint limit of figure 6.10."""
    reach = robot.fkm(REACH_GOAL)
    beyond_obstacle = robot.fkm(OBSTACLE_GOAL)
    past_elbow_limit = robot.fkm(JOINT_LIMIT_GOAL)
    return [
        Experiment(
            "pose",
            PoseTask(reach),
            {"LP": LPLaw(robot, LP_PARAMS["pose"]), "cascade": CascadeLaw(robot)},
        ),
        Experiment(
            "position",
            PositionTask(dq.translation(reach)[1:]),
            {"LP": LPLaw(robot, LP_PARAMS["position"]), "cascade": CascadeLaw(robot)},
        ),
        Experiment(
            "obstacle",
            PoseTask(beyond_obstacle),
            {
                "LP vector field": LPLaw(robot, LP_PARAMS["obstacle"]),
                "LP border": LPLaw(robot, BORDER_PARAMS),
                "LP conservative": LPLaw(robot, LPParams(obstacle_mode="conservative")),
            },
            (OBSTACLE,),
        ),
        Experiment(
            "joint limit",
            PoseTask(past_elbow_limit),
            {"LP": LPLaw(robot), "pinv": PseudoinverseLaw(robot)},
        ),
    ]


def summary_row(experiment: Experiment, law_name: str, run: Run, robot: MobileManipulator) -> dict:
    """What the demo prints for one run."""
    configurations = np.array(run.configurations)
    arm = configurations[:, 3:]
    beyond = np.maximum(arm - robot.q_max[3:], robot.q_min[3:] - arm).max()
    effort = control_effort(run)
    row = {
        "experiment": experiment.name,
        "law": law_name,
        "converged": run.converged,
        "steps": len(run.outputs),
        "final_error": run.final_error,
        "median_nonzero": float(np.median([out.nonzero for out in run.outputs])),
        "median_practical_nonzero": float(
            np.median([out.practical_nonzero for out in run.outputs])
        ),
        "worst_joint_overrun": float(max(beyond, 0.0)),
        "effort_velocity_l1": effort.velocity_l1,
        "effort_velocity_l2": effort.velocity_l2,
        "median_step_us": float(np.median([out.solve_time_s for out in run.outputs]) * 1e6),
    }
    for obstacle in experiment.obstacles:
        gap = np.hypot(configurations[:, 0] - obstacle.x, configurations[:, 1] - obstacle.y)
        row["min_obstacle_clearance"] = float(
            (gap - obstacle.radius - robot.base.body_radius).min()
        )
    return row


def run_demo(robot_file: Path = ROBOT_FILE) -> list[dict]:
    robot = MobileManipulator.from_yaml(robot_file)
    rows = []
    for experiment in experiments(robot):
        for law_name, law in experiment.laws.items():
            run = integrate(law, HOME, experiment.task, DT, STEPS, obstacles=experiment.obstacles)
            rows.append(summary_row(experiment, law_name, run, robot))
    return rows


COLUMNS = ("experiment", "law", "converged", "steps", "final_error", "median_nonzero",
           "median_practical_nonzero", "worst_joint_overrun", "effort_velocity_l1",
           "effort_velocity_l2", "median_step_us", "min_obstacle_clearance")
"""The demo's table: these figures of each run (a clearance where there is an obstacle)."""


def format_table(rows: list[dict]) -> str:
    return table([{key: row.get(key) for key in COLUMNS} for row in rows],
                 floatfmt=".3g")
