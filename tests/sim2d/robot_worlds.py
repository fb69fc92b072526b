"""Worlds of the robots of deploy/robots, started mid-range and run in steps of ``DT``."""

from __future__ import annotations

import numpy as np

from profiles.deploy_files import ROBOTS_DIR
from sim2d.world import World
from wbc.robot import MobileManipulator

DT = 0.01


def robot(name: str) -> MobileManipulator:
    return MobileManipulator.from_yaml(ROBOTS_DIR / f"{name}.yaml")


def run(world: World, seconds: float) -> None:
    for _ in range(round(seconds / DT)):
        world.step(DT)


def middle(robot: MobileManipulator) -> np.ndarray:
    """A start with every arm joint in the middle of its range, the base at (1, 2, 0.3)."""
    arm = 0.5 * (robot.q_min[3:] + robot.q_max[3:])
    return np.concatenate(([1.0, 2.0, 0.3], arm))
