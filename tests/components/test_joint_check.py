"""A state or command whose joints are not the robot description's (a wrong size, wrong
names) is refused by the component that receives it, counted on its status and said in one
line naming the joints expected; the controller answers it with zero commands."""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

from components.arm_driver import ArmDriver
from components.control_step import REFUSED_STATE, ControlStep
from components.lp_controller import LPController
from components.runtime import Component, Node
from components.scripted_publisher import ScriptedPublisher
from components.simulator import Simulator
from components.state_estimator import StateEstimator
from components.supervisor import Supervisor
from messages.commands import ArmCommand
from messages.goal import Goal
from messages.header import Header
from messages.joints import JointStates
from messages.state import RobotState
from profiles.deploy_files import DEPLOY, ROBOT_FILE
from profiles.profile import load_profile
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
HEADER = Header(stamp_ns=10**9, frame="world", seq=0, source="test")
EXPECTED = "the robot's are 5 (q1, q2, q3, q4, q5)"
WRONG = {
    "wrong size": ("q1", "q2", "q3", "q4", "q5", "q6"),
    "wrong names": ("waist", "shoulder", "elbow", "wrist", "hand"),
}


def state(names: tuple[str, ...]) -> RobotState:
    q = np.zeros(3 + len(names))
    return RobotState(
        header=HEADER,
        base_pose=(0.0, 0.0, 0.0),
        arm_joints=tuple(q[3:]),
        joint_names=names,
        end_effector=tuple(ROBOT.fkm(np.zeros(ROBOT.dof))),
        valid=True,
        age_s=0.0,
    )


def command(names: tuple[str, ...]) -> ArmCommand:
    return ArmCommand(header=HEADER, joint_velocities=(0.1,) * len(names), joint_names=names)


def joint_states(names: tuple[str, ...]) -> JointStates:
    zeros = (0.0,) * len(names)
    return JointStates(header=HEADER, names=names, positions=zeros, velocities=zeros)


@pytest.mark.parametrize("wrong", WRONG)
def test_the_control_step_answers_a_state_of_other_joints_with_zero(wrong: str) -> None:
    control = ControlStep("lp", LPLaw, ROBOT, LPParams())
    step = control.step(state(WRONG[wrong]), HEADER.stamp_ns, 0.5)
    assert step.status == REFUSED_STATE
    assert EXPECTED in step.reason
    assert step.joints == (0.0,) * 5 and step.wheels == (0.0,) * 4


@pytest.fixture(scope="module")
def components() -> Iterator[dict[str, Component]]:
    """The receiving components of the simulated profile, on open nodes, not started."""
    profile = load_profile(DEPLOY / "sim_supervised.yaml")
    made = {}
    with (
        Node(profile, "simulator", Simulator.params) as sim,
        Node(profile, "state_estimator", StateEstimator.params) as estimator,
        Node(profile, "controller", LPController.params) as controller,
        Node(profile, "supervisor", Supervisor.params) as supervisor,
    ):
        made["simulator"] = Simulator(sim)
        made["state_estimator"] = StateEstimator(estimator)
        made["controller"] = LPController(controller)
        made["supervisor"] = Supervisor(supervisor)
        yield made
        made["supervisor"].shutdown()
        made["simulator"].shutdown()


RECEIVERS: dict[str, tuple[str, Callable[[Component], Callable], Callable]] = {
    "simulator": (
        "refused_arm_commands",
        lambda c: lambda m: c._take_command("arm/command", m),
        command,
    ),
    "state_estimator": ("refused_joint_states", lambda c: c.on_joints, joint_states),
    "controller": ("refused_states", lambda c: c.on_state, state),
    "supervisor": ("refused_states", lambda c: c.on_state, state),
}


@pytest.mark.parametrize("wrong", WRONG)
@pytest.mark.parametrize("receiver", RECEIVERS)
def test_a_message_of_other_joints_is_refused_counted_and_said(
    components: dict[str, Component],
    receiver: str,
    wrong: str,
    caplog: pytest.LogCaptureFixture,
) -> None:
    counter, handler, message = RECEIVERS[receiver]
    component = components[receiver]
    before = component.node.counters[counter]
    component.node._warnings._last_ns.clear()  # each case logs its own first line
    with caplog.at_level(logging.WARNING):
        handler(component)(message(WRONG[wrong]))
    assert component.node.counters[counter] == before + 1
    assert f"{len(WRONG[wrong])} joints ({', '.join(WRONG[wrong])})" in caplog.text
    assert EXPECTED in caplog.text


def test_the_simulator_keeps_the_last_good_arm_command(
    components: dict[str, Component],
) -> None:
    simulator = components["simulator"]
    good = command(ROBOT.joint_names)
    simulator._take_command("arm/command", good)
    simulator._take_command("arm/command", command(WRONG["wrong names"]))
    assert simulator.arm_command is good


def test_the_arm_driver_holds_on_a_command_of_other_joints(
    caplog: pytest.LogCaptureFixture, tmp_path: Path
) -> None:
    # A port of its own that is absent (the emulated profile's is another test's emulator).
    text = (DEPLOY / "emulated.yaml").read_text()
    text = text.replace("/tmp/parsimony-emulated/servos", str(tmp_path / "servos"))
    emulated = tmp_path / "emulated.yaml"
    emulated.write_text(text.replace("extends: hardware.yaml", f"extends: {DEPLOY}/hardware.yaml"))
    profile = load_profile(emulated)
    assert profile.component("arm_driver").params["port"] == str(tmp_path / "servos")
    with Node(profile, "arm_driver", ArmDriver.params) as node:
        driver = ArmDriver(node)  # its port is absent: it holds, and counts what it refuses
        with caplog.at_level(logging.WARNING):
            driver.on_command(command(WRONG["wrong names"]))
        assert node.counters["refused_commands"] == 1
        assert EXPECTED in caplog.text


def test_the_scripted_publisher_sends_no_state_of_another_size(
    caplog: pytest.LogCaptureFixture,
) -> None:
    profile = load_profile(DEPLOY / "controllers.yaml")
    with Node(profile, "publisher", ScriptedPublisher.params) as node:
        publisher = ScriptedPublisher(node)
        node.params.set("joints", [0.1, 0.2, 0.3])
        with caplog.at_level(logging.WARNING):
            publisher.publish()
        assert node.counters["refused_states"] == 1
        assert "3 given, " + EXPECTED in caplog.text


def test_a_goal_whose_arm_is_not_the_robots_size_is_refused() -> None:
    control = ControlStep("lp", LPLaw, ROBOT, LPParams())
    goal = Goal(header=HEADER, task="point", point=(1.0, 0.0), arm=(0.0,) * 7, lookahead=0.1)
    with pytest.raises(ValueError, match="arm: 7 joints, the robot's are q1, q2, q3, q4, q5"):
        control.take_goal(goal)
    step = control.step(state(ROBOT.joint_names), HEADER.stamp_ns, 0.5)
    assert step.status == "goal refused" and "arm: 7 joints" in step.reason
