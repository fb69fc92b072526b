"""The control step (components/control_step.py): a step that commands zero instead of the
law's u tells the law, so a law that prices the change of u (the input change term) starts
again from rest, as the robot does; a u that is not finite and a goal whose gains leave their
bounds command zero and say why, never raise."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from components.control_step import ControlStep
from messages.goal import Goal
from messages.header import Header
from messages.state import RobotState
from profiles.deploy_files import ROBOT_FILE
from studies.gain_sets import LP_PARAMS, input_change_gains
from wbc.geometry.scenarios import DT, HOME, REACH_GOAL
from wbc.laws.cascade_law import CascadeLaw, CascadeParams
from wbc.laws.gains import gain_specs
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.qp_law import QPLaw, QPParams
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
STEP_NS = int(DT * 1e9)
STALE_S = 0.5


def state(q: np.ndarray, stamp_ns: int, end_effector: np.ndarray | None = None) -> RobotState:
    """A valid state at ``q``, its end effector's pose ``fkm(q)`` unless given."""
    pose = ROBOT.fkm(q) if end_effector is None else end_effector
    return RobotState(
        header=Header(stamp_ns=stamp_ns, frame="world", seq=0, source="test"),
        base_pose=tuple(q[:3]),
        arm_joints=tuple(q[3:]),
        end_effector=tuple(pose),
        valid=True,
        age_s=0.0,
    )


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


LAWS = {"lp": (LPLaw, LPParams), "qp": (QPLaw, QPParams), "cascade": (CascadeLaw, CascadeParams)}
HEADER = Header(stamp_ns=0, frame="world", seq=0, source="test")
GOAL = Goal(header=HEADER, task="pose", pose=tuple(ROBOT.fkm(REACH_GOAL)))
FAR = (1e300, -1e300, 1e300)
"""A base pose whose program overflows: the QP law's u was all NaN, reported optimal."""


@pytest.mark.parametrize("law", LAWS)
def test_a_base_pose_of_1e300_commands_zero_or_a_finite_u_and_never_raises(law: str) -> None:
    """The QP's NaN went to ``wheel_speeds`` before the step's own check: ValueError, and no
    command at all for that state. Now: zero, status ``non-finite`` (the LP's HiGHS gives up,
    the cascade's u is finite)."""
    law_type, gains_type = LAWS[law]
    control = ControlStep(law, law_type, ROBOT, gains_type())
    control.take_goal(GOAL)
    q = HOME.copy()
    q[:3] = FAR
    with np.errstate(over="ignore", invalid="ignore"):  # e's norm overflows, as it should
        step = control.step(state(q, STEP_NS, ROBOT.fkm(HOME)), STEP_NS, STALE_S)
    assert all(np.isfinite((*step.wheels, *step.joints))), step
    if step.status != "optimal":
        assert step.wheels == (0.0,) * 4 and step.joints == (0.0,) * 5
    if law == "qp":
        assert step.status == "non-finite", step


@pytest.mark.parametrize("value", [1e300, 1e-300])
@pytest.mark.parametrize("name", ["eta", "beta"])
def test_a_goal_whose_gain_leaves_its_bounds_is_refused_naming_the_field_and_them(
    name: str, value: float
) -> None:
    """eta or beta of 1e300 or 1e-300 passes the goal's schema (a positive number): refused
    (ValueError), and every step until the next goal commands zero with the status ``goal
    refused`` and the gain's bounds, as ``wbc.laws.gains`` declares them."""
    control = ControlStep("lp", LPLaw, ROBOT, LPParams())
    control.take_goal(GOAL)
    with pytest.raises(ValueError, match=name):
        control.take_goal(GOAL.model_copy(update={name: value}))
    spec = next(spec for spec in gain_specs(LPParams) if spec.name == name)
    for stamp in (STEP_NS, 2 * STEP_NS):
        step = control.step(state(HOME, stamp), stamp, STALE_S)
        assert step.status == "goal refused" and step.joints == (0.0,) * 5
        assert f"{name}: expected {spec.expected()}" in step.reason, step.reason
    control.take_goal(GOAL)
    assert control.step(state(HOME, 3 * STEP_NS), 3 * STEP_NS, STALE_S).status == "optimal"
