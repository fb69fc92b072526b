"""The LP law's outputs along fixed closed loops, bit for bit: a change made for speed (the
glue of its step) leaves every command, objective, status and active set as they were.

The digests were taken with the law as it stood at commit 2fd7860 (before the last cut of its
glue), and every output stepped against that law's; a change that moves any bit of any output
changes them. They hold on one machine's floating point, as the pose experiment's lockstep
commands digest does.
"""

from __future__ import annotations

import hashlib
from dataclasses import replace

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE, ROBOTS_DIR
from studies.gain_sets import OBSTACLE_PARAMS, POSE_PARAMS, input_change_gains
from studies.step_timing import scenario
from wbc.geometry.obstacles import Obstacle
from wbc.geometry.scenarios import DT, HOME, OBSTACLE, OBSTACLE_GOAL, REACH_GOAL
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

STEPS = 150


def outputs_digest(
    law: LPLaw, start: np.ndarray, goal: np.ndarray, obstacles: tuple[Obstacle, ...] = ()
) -> str:
    """SHA-256 of every output of ``law`` along its own closed loop from ``start`` towards the
    pose of ``goal`` (q += u dt), its u once stopped and its state once forgotten (``reset``)."""
    task, q, digest = PoseTask(law.robot.fkm(goal)), np.array(start, float), hashlib.sha256()
    for step in range(STEPS):
        if step == STEPS // 3:
            law.stopped()
        if step == STEPS // 2:
            law.reset()
        out = law.step(q, task, DT, obstacles)
        fields = (out.status, out.objective, out.active_constraints, out.nonzero)
        digest.update(out.u.tobytes() + repr((*fields, out.practical_nonzero)).encode())
        q = q + out.u * DT
    return digest.hexdigest()


def little_john(params: LPParams, goal: np.ndarray, *obstacles: Obstacle) -> tuple:
    robot = MobileManipulator.from_yaml(ROBOT_FILE)
    return LPLaw(robot, params), HOME, goal, obstacles


def snake() -> tuple:
    robot = MobileManipulator.from_yaml(ROBOTS_DIR / "snake12.yaml")
    return LPLaw(robot), *scenario(robot), ()


CASES = {
    "reach": (
        lambda: little_john(POSE_PARAMS, REACH_GOAL),
        "db6a8c11082ff7cb683024feac259704476ba64b10a0ccb53da05054cda76f82",
    ),
    "obstacle": (
        lambda: little_john(OBSTACLE_PARAMS, OBSTACLE_GOAL, OBSTACLE),
        "7ea80041577dc0e0111db89c5ab87f6552673e8a504b5cec6dd5bd2248b60740",
    ),
    "input_change": (
        lambda: little_john(replace(POSE_PARAMS, **input_change_gains()), REACH_GOAL),
        "7030a957929684e1bd75ceeb362cd91cba9b7e7e9ec7fdd8c3fc6ec6b3ad79c4",
    ),
    "snake12": (snake, "b90346f0507ac3c96c45baf2f57673852d8e51bcbe7893838e65eda6434af1f2"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_lp_outputs_are_those_of_the_law_before_its_glue_was_cut(case: str) -> None:
    build, expected = CASES[case]
    assert outputs_digest(*build()) == expected
