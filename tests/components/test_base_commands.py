"""What the control step tells the base of each kind: a differential base the unicycle's wheel
speeds, an omnidirectional base (x', y') in its own frame, a fixed base nothing; and the
controller's arm command names the robot's joints."""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.control_step import ControlStep, base_command
from messages.goal import Goal
from messages.header import Header
from profiles.deploy_files import ROBOT_FILE, ROBOTS_DIR
from tests.robot_states import state_at
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.robot import MobileManipulator

HEADER = Header(stamp_ns=10**9, frame="world", seq=0, source="test")


def robot(name: str) -> MobileManipulator:
    return MobileManipulator.from_yaml(ROBOTS_DIR / f"{name}.yaml")


def test_a_differential_base_gets_the_unicycles_wheel_speeds() -> None:
    base = MobileManipulator.from_yaml(ROBOT_FILE).base
    wheels, lateral = base_command(np.array([0.1, 0.0, 0.5]), 0.0, base)
    half_track = 0.5 * base.wheel_base * 0.5
    assert wheels == pytest.approx((0.1, 0.5, 0.1 - half_track, 0.1 + half_track))
    assert lateral == 0.0


def test_an_omnidirectional_base_gets_its_own_frames_velocities() -> None:
    base = robot("youbot").base
    phi = 0.5 * math.pi  # facing +y: x' is to its right
    wheels, lateral = base_command(np.array([0.1, 0.2, 0.3]), phi, base)
    assert wheels == pytest.approx((0.2, 0.3, 0.0, 0.0))
    assert lateral == pytest.approx(-0.1)


def test_a_fixed_base_gets_nothing() -> None:
    assert base_command(np.array([0.1, 0.2, 0.3]), 0.0, robot("ur5e_fixed").base) == (
        (0.0, 0.0, 0.0, 0.0),
        0.0,
    )


@pytest.mark.parametrize("name", ["youbot", "ur5e_fixed", "arm7_differential"])
def test_the_step_commands_every_joint_of_the_robot(name: str) -> None:
    arm = robot(name)
    q = np.concatenate(([0.0, 0.0, 0.0], 0.5 * (arm.q_min[3:] + arm.q_max[3:])))
    goal = q.copy()
    goal[3:] += 0.1 * (arm.q_max[3:] - arm.q_min[3:]) / 2  # a reachable pose nearby
    control = ControlStep("lp", LPLaw, arm, LPParams())
    control.take_goal(Goal(header=HEADER, task="pose", pose=tuple(arm.fkm(goal))))
    state = state_at(arm, q, HEADER)
    step = control.step(state, HEADER.stamp_ns, 0.5)
    assert step.status == "optimal", step.reason
    assert len(step.joints) == arm.arm_dof and any(v != 0.0 for v in step.joints)
    if arm.base.kind == "fixed":
        assert step.wheels == (0.0, 0.0, 0.0, 0.0) and step.lateral == 0.0
    if arm.base.kind != "differential":
        assert step.wheels[2:] == (0.0, 0.0)  # no wheels
