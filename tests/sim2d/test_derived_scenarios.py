"""The set-ups derived for a robot of the zoo other than Little John (sim2d.scenarios.derived):
a goal the robot reaches, inside its limits, that the ceiling camera sees."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from profiles.deploy_files import zoo
from sim2d.scenarios import DECLARED_FOR, DERIVED, NAMES, goal_above, scenario
from tests.sim2d.sim_scene import camera, markers, scene
from wbc import dq
from wbc.laws.kinematic_run import integrate
from wbc.laws.lp_law import LPLaw
from wbc.robot import MobileManipulator
from wbc.task import PoseTask, PositionTask

OTHERS = [p for p in zoo() if p.stem != DECLARED_FOR]
"""The zoo but Little John, whose set-ups are declared (tests/sim2d/test_scenarios.py)."""
DT, STEPS = 0.02, 3000
"""The experiments' control period, and a run's 60 s."""


def names_for(robot: MobileManipulator) -> tuple[str, ...]:
    """'obstacle' but on a fixed base, or a body too large for the way past the obstacle."""
    small = robot.base.kind != "fixed" and robot.base.body_radius < 0.5
    return DERIVED if small else DERIVED[:2]


@pytest.mark.parametrize("path", OTHERS, ids=[p.stem for p in OTHERS])
@pytest.mark.parametrize(("name", "seed"), [("pose", None), ("position", 1)])
def test_the_lp_reaches_a_derived_goal_from_its_start_inside_the_limits(
    path: Path, name: str, seed: int | None
) -> None:
    """In a kinematic closed loop at the experiments' period, within their 60 s ('obstacle'
    moves the same goal past an obstacle; the whole loop's test runs it)."""
    robot = MobileManipulator.from_yaml(path)
    setup = scenario(name, robot, seed)
    start = np.array(setup.start)
    assert np.all(start >= robot.q_min) and np.all(start <= robot.q_max)
    assert setup.goal_offset is not None
    goal = goal_above(setup.bin, 0.0, setup.goal_offset)
    position = PositionTask(dq.translation(goal)[1:])
    task = position if setup.task == "position" else PoseTask(goal)
    run = integrate(LPLaw(robot), start, task, DT, STEPS, tolerance=0.01)
    assert run.converged, (name, seed, run.final_error)
    q = np.array(run.configurations)
    assert np.all(q >= robot.q_min - 1e-9) and np.all(q <= robot.q_max + 1e-9)


@pytest.mark.parametrize("path", OTHERS, ids=[p.stem for p in OTHERS])
def test_every_marker_of_a_derived_set_up_is_in_the_image(path: Path) -> None:
    robot = MobileManipulator.from_yaml(path)
    view, depth = camera(), scene().camera.position[2]
    for name in names_for(robot):
        for seed in (None, *range(10)):
            for what, x, y, z, size in markers(scenario(name, robot, seed)):
                ((u, v),) = view.project(np.array([[x, y, z]]))
                half = 0.5 * size * view.fx / (depth - z)
                assert half < u < view.width - 1 - half, (name, seed, what, u)
                assert half < v < view.height - 1 - half, (name, seed, what, v)


@pytest.mark.parametrize("path", OTHERS, ids=[p.stem for p in OTHERS])
def test_little_johns_own_set_ups_are_refused_naming_the_choices(path: Path) -> None:
    robot = MobileManipulator.from_yaml(path)
    for name in set(NAMES) - set(names_for(robot)):
        with pytest.raises(ValueError, match=f"for {robot.name} choose pose, position"):
            scenario(name, robot)
