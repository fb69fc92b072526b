"""The arm's conditioning (wbc/conditioning.py): the smallest singular value of its Jacobian."""

from __future__ import annotations

import math

import numpy as np

from tests.wbc.wbc_scenarios import robot
from wbc.conditioning import smallest_singular_value
from wbc.geometry.scenarios import HOME

MODEL = robot()


def test_conditioning_vanishes_where_the_arm_loses_a_direction() -> None:
    # The wrist rolled a quarter turn puts the wrist pitch axis parallel to the shoulder's and
    # the elbow's: the three then move the gripper in the arm's plane, as the base's forward
    # motion does, and nothing turns it about the vertical without swinging it sideways.
    rolled = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, math.pi / 2, 0.0])
    assert smallest_singular_value(MODEL, rolled) < 1e-9
    assert smallest_singular_value(MODEL, HOME) > 0.01
