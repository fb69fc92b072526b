"""The control step (components/control_step.py) and the u its law remembers: a step that
commands zero instead of the law's u tells the law, so a law that prices the change of u
(the input change term) starts again from rest, as the robot does."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from components.control_step import ControlStep
from deploy import ROBOT_FILE
from messages.goal import Goal
from messages.header import Header
from messages.state import RobotState
from parsimony.kinematic_demo import LP_PARAMS, input_change_gains
from wbc.lp_law import LPLaw
from wbc.robot import MobileManipulator
from wbc.scenarios import DT, HOME, REACH_GOAL

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
STEP_NS = int(DT * 1e9)
STALE_S = 0.5


def state(q: np.ndarray, stamp_ns: int) -> RobotState:
    return RobotState(header=Header(stamp_ns=stamp_ns, frame="world", seq=0, source="test"),
                      base_pose=tuple(q[:3]), arm_joints=tuple(q[3:]),
                      end_effector=tuple(ROBOT.fkm(q)), valid=True, age_s=0.0)  # fmt: skip


@pytest.mark.parametrize("hold", ["a stale state", "a zero sent without a state"])
def test_a_held_step_starts_the_law_again_from_rest(hold: str) -> None:
    """Moving under the input change term (w 3: its band a bound), then zero sent, for a state
    too old or with no state at all (the controller's timer, a stopped clock, a bad
    parameter): the next u speeds up from 0 by at most s = v dt / T an entry, not from the u
    the law gave before the hold."""
    smooth = input_change_gains()
    gains = dataclasses.replace(LP_PARAMS["pose"], **{**smooth, "input_change": 3.0})
    control = ControlStep("lp", LPLaw, ROBOT, gains)
    header = Header(stamp_ns=0, frame="world", seq=0, source="test")
    control.take_goal(Goal(header=header, task="pose", pose=tuple(ROBOT.fkm(REACH_GOAL))))
    q, stamp = HOME.copy(), 0
    for _ in range(40):
        stamp += STEP_NS
        step = control.step(state(q, stamp), stamp, STALE_S)
        assert step.status == "optimal"
        q = q + DT * step.output.u
    moving = step.output.u
    ramp = ROBOT.velocity_max * DT / smooth["input_change_ramp"]
    assert np.any(np.abs(moving) > ramp + 1e-6), "the run must be faster than one ramp step"
    if hold == "a stale state":
        stamp += STEP_NS
        held = control.step(state(q, stamp), stamp + int(2 * STALE_S * 1e9), STALE_S)
    else:  # the controller's timer, between two states
        held = control.zero(stamp + STEP_NS // 2, "stale", "no robot/state for 0.51 s")
    assert held.status == "stale" and held.joints == (0.0,) * 5
    stamp += STEP_NS
    after = control.step(state(q, stamp), stamp, STALE_S)
    assert after.status == "optimal"
    assert np.all(np.abs(after.output.u) <= ramp + 1e-9)
