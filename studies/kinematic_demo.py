"""The kinematic demo: the experiments of section 6.2 integrated as q += u dt, LP against cascade.

No simulator and no network: the laws of `wbc` on the robot model, at 50 Hz, printing for each
experiment whether it converged, in how many steps, how many joints it used and the control
effort of table 6.1.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from outputs.stdout import table
from profiles.deploy_files import ROBOT_FILE
from studies.gain_sets import BORDER_PARAMS, LP_PARAMS, TABLE_PARAMS, WITHOUT_ARM_ROWS
from wbc import dq
from wbc.geometry.arm_clearance import PenetrationCount, part_clearances
from wbc.geometry.obstacles import Obstacle, least_clearance, split
from wbc.geometry.scenarios import (
    DT,
    HOME,
    JOINT_LIMIT_GOAL,
    OBSTACLE,
    OBSTACLE_GOAL,
    REACH_GOAL,
    TABLE,
    TABLE_GOAL,
    TABLE_START,
)
from wbc.laws.cascade_law import CascadeLaw
from wbc.laws.kinematic_run import Run, control_effort, integrate
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.pinv_law import PseudoinverseLaw
from wbc.robot import MobileManipulator
from wbc.task import PoseTask, PositionTask, Task

STEPS = 4000


@dataclass(frozen=True)
class Experiment:
    name: str
    task: Task
    laws: dict[str, object]
    obstacles: tuple[Obstacle, ...] = ()
    start: np.ndarray = field(default_factory=HOME.copy)


def experiments(robot: MobileManipulator) -> list[Experiment]:
    """Pose (6.2.1), position (6.2.2), obstacle (6.2.3), the joint limit of figure 6.10, and
    the reach over a table's edge."""
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
        Experiment(
            "table",
            PoseTask(robot.fkm(TABLE_GOAL)),
            {
                "LP": LPLaw(robot, TABLE_PARAMS),
                "LP without arm rows": LPLaw(robot, WITHOUT_ARM_ROWS),
            },
            (TABLE,),
            TABLE_START,
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
    circles, solids = split(experiment.obstacles)
    if circles:
        row["min_obstacle_clearance"] = least_clearance(
            configurations[:, :2], circles, robot.base.body_radius
        )
    if solids:
        count = PenetrationCount()
        least = np.inf
        for q in configurations:
            clearances = part_clearances(robot, q, solids)
            count.update(clearances)
            least = min(least, float(clearances.min()))
        row["min_arm_clearance"], row["arm_penetrations"] = least, count.count
    return row


def run_demo(robot_file: Path = ROBOT_FILE) -> list[dict]:
    robot = MobileManipulator.from_yaml(robot_file)
    rows = []
    for experiment in experiments(robot):
        for law_name, law in experiment.laws.items():
            run = integrate(
                law, experiment.start, experiment.task, DT, STEPS, obstacles=experiment.obstacles
            )
            rows.append(summary_row(experiment, law_name, run, robot))
    return rows


COLUMNS = (
    "experiment",
    "law",
    "converged",
    "steps",
    "final_error",
    "median_nonzero",
    "median_practical_nonzero",
    "worst_joint_overrun",
    "effort_velocity_l1",
    "effort_velocity_l2",
    "median_step_us",
    "min_obstacle_clearance",
    "min_arm_clearance",
    "arm_penetrations",
)
"""The demo's table: these figures of each run (clearances where there are obstacles)."""


def format_table(rows: list[dict]) -> str:
    return table([{key: row.get(key) for key in COLUMNS} for row in rows], floatfmt=".3g")
