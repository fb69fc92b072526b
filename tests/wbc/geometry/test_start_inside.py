"""A robot that starts inside a solid (wbc.geometry.start_inside): one line per solid naming it, and
what the robot then does, checked on the laws: no part inside goes deeper, none is pushed out."""

from __future__ import annotations

import numpy as np
import pytest

from tests.wbc.wbc_scenarios import integrate, pose_task, robot
from wbc.geometry.arm_clearance import part_clearances
from wbc.geometry.obstacles3d import Cylinder, Plane
from wbc.geometry.scenarios import HOME, REACH_GOAL
from wbc.geometry.start_inside import CONSEQUENCE, inside_at_start
from wbc.laws.lp_law import LPLaw
from wbc.laws.qp_law import QPLaw

MODEL = robot()
WALL = Plane((-1.0, 0.0, 0.0), -0.15, name="wall")
"""The solid x > 0.15: through the arm at HOME, the goal of 6.2.1 beyond it."""
POLE = Cylinder(0.0, 0.0, 0.05, 1.0, "pole")
"""Up through the base's middle."""
CLEAR = Cylinder(3.0, 0.0, 0.05, 1.0, "far pole")


def test_each_solid_the_robot_starts_inside_gets_one_line_naming_it_and_what_follows() -> None:
    lines = inside_at_start(MODEL, HOME, [WALL, CLEAR, POLE], ["the wall", "far", "the pole"])
    assert len(lines) == 2
    wall, pole = lines
    assert wall.startswith("the robot starts inside the wall: its ") and "gripper" in wall
    assert pole.startswith("the robot starts inside the pole: its base (the base 0.")
    assert all(line.endswith(CONSEQUENCE) for line in lines)
    assert inside_at_start(MODEL, HOME, [CLEAR], ["far"]) == ()
    assert inside_at_start(MODEL, HOME, [], []) == ()


@pytest.mark.parametrize("law", [LPLaw, QPLaw])
def test_a_part_inside_a_solid_never_goes_deeper_and_the_robot_may_stop_short(law) -> None:
    """What the line says: through the wall, the robot reaching beyond it takes no part deeper
    (the arm rows) and stops short of the goal; no row pushed the parts out."""
    run = integrate(law(MODEL), HOME, pose_task(MODEL, REACH_GOAL), 500, obstacles=[WALL])
    depths = np.array([part_clearances(MODEL, q, [WALL])[:, 0] for q in run.configurations])
    inside = depths[0] < 0.0
    assert inside.any()
    assert np.all(np.diff(depths[:, inside], axis=0) >= -1e-6)
    assert not run.converged and run.final_error > 0.1
    assert np.any(depths[-1] < 0.0)
