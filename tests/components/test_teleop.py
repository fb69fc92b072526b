"""Teleoperation: a hand's command under the robot's limits (``control_step.teleop_step``) and
the keys of `parsimony teleop` (``parsimony.commands.teleop.press``)."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import threading
import time

import numpy as np
import zenoh

from components.control_step import REFUSED_STATE, TELEOP, teleop_step
from components.lp_controller import LPController
from components.runtime import Node
from components.stop_latch import stop_state
from messages import codec, topics
from messages.diagnostics import ControllerDiagnostics
from messages.goal import Goal
from messages.header import Header
from messages.state import RobotState
from messages.teleop import TeleopCommand
from parsimony.commands.teleop import Hand, press
from profiles.deploy_files import DEPLOY, ROBOT_FILE
from tests.components.conftest import DEADLINE_S
from tests.components.supervised import header, met_at, supervised
from wbc.geometry.scenarios import HOME, REACH_GOAL
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
HEADER = Header(stamp_ns=7, frame="world", seq=0, source="test")
IDENTITY = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def state(arm: tuple[float, ...] = (0.0,) * 5, phi: float = 0.7) -> RobotState:
    return RobotState(
        header=HEADER,
        base_pose=(1.0, 2.0, phi),
        arm_joints=arm,
        joint_names=ROBOT.joint_names,
        end_effector=IDENTITY,
        valid=True,
        age_s=0.0,
    )


def hand(**fields: object) -> TeleopCommand:
    return TeleopCommand(header=HEADER, **fields)


def test_the_base_goes_as_asked_inside_its_limits() -> None:
    slow = teleop_step(ROBOT, state(), hand(forward=0.05, turn=0.1))
    forward, angular, left, right = slow.wheels
    assert slow.status == TELEOP and slow.stamp_ns == 7
    assert math.isclose(forward, 0.05) and math.isclose(angular, 0.1)
    assert slow.joints == (0.0,) * 5
    fast = teleop_step(ROBOT, state(), hand(forward=100.0, turn=0.0))
    limits = ROBOT.velocity_max[:2]
    assert 0 < fast.wheels[0] <= float(np.hypot(*limits)) + 1e-9
    assert max(abs(fast.wheels[2]), abs(fast.wheels[3])) <= ROBOT.base.wheel_speed_max + 1e-9


def test_one_joint_moves_inside_its_velocity_and_joint_limits() -> None:
    name, limit = ROBOT.joint_names[1], ROBOT.velocity_max[4]
    step = teleop_step(ROBOT, state(), hand(joint=name, joint_velocity=100.0))
    assert step.joints == (0.0, limit, 0.0, 0.0, 0.0)
    top = (0.0, float(ROBOT.q_max[4]), 0.0, 0.0, 0.0)
    assert teleop_step(ROBOT, state(top), hand(joint=name, joint_velocity=0.2)).joints[1] == 0
    assert teleop_step(ROBOT, state(top), hand(joint=name, joint_velocity=-0.2)).joints[1] == -0.2
    unknown = teleop_step(ROBOT, state(), hand(joint="elbow", joint_velocity=0.2))
    assert unknown.joints == (0.0,) * 5 and unknown.wheels == (0.0,) * 4
    assert "no joint 'elbow'" in unknown.reason
    other = state().model_copy(update={"joint_names": ("a", "b", "c", "d", "e")})
    assert teleop_step(ROBOT, other, hand(forward=0.1)).status == REFUSED_STATE


def test_the_keys() -> None:
    speeds = (0.1, 0.5, 0.3)
    held = press("w", Hand(), speeds, 5)
    assert held == Hand(forward=0.1)
    assert press("d", held, speeds, 5) == Hand(forward=0.1, turn=-0.5)
    assert press("3", held, speeds, 5) == Hand(joint=2)
    assert press("k", Hand(joint=2), speeds, 5) == Hand(joint=2, joint_velocity=-0.3)
    assert press(" ", Hand(forward=0.1, joint=2, joint_velocity=0.3), speeds, 5) == Hand(joint=2)
    assert press("9", held, speeds, 5) == held and press("x", held, speeds, 5) == held
    assert press("q", held, speeds, 5) is None


def matched(publisher: zenoh.Publisher) -> None:
    """Once ``publisher``'s session knows a subscriber of its key (Zenoh drops a message that
    has none)."""
    found = threading.Event()
    listener = publisher.declare_matching_listener(lambda status: status.matching and found.set())
    if publisher.matching_status.matching:
        found.set()
    assert found.wait(DEADLINE_S), f"no subscriber of {publisher.key_expr} within {DEADLINE_S} s"
    listener.undeclare()


def test_the_controller_yields_to_a_hand_and_resumes_only_on_a_new_goal(deployed) -> None:
    """The LP controller in process on deploy/hardware.yaml's settings (wall clock)."""
    system = deployed(DEPLOY / "hardware.yaml")
    namespace = system.profile.namespace
    diagnostics = system.inbox(topics.CONTROL_DIAGNOSTICS)
    put = {
        topic: system.router.declare_publisher(topic.key(namespace))
        for topic in (topics.ROBOT_STATE, topics.CONTROL_GOAL, topics.TELEOP_COMMAND)
    }

    def send(topic: topics.Topic, message: object) -> None:
        put[topic].put(codec.encode(message))

    def step(**hand_fields: object) -> ControllerDiagnostics:
        """A hand's command (when given), then a state; the diagnostics answering it."""
        stamp = time.time_ns()
        if hand_fields:
            send(topics.TELEOP_COMMAND, hand(**hand_fields))
        header = Header(stamp_ns=stamp, frame="world", seq=0, source="test")
        send(topics.ROBOT_STATE, state().model_copy(update={"header": header}))
        return diagnostics.wait_for(lambda d: d.header.stamp_ns == stamp, "of the state")

    def goal(x: float) -> Goal:
        header = Header(stamp_ns=time.time_ns(), frame="world", seq=0, source="test")
        return Goal(header=header, task="position", position=(x, 2.0, 0.4))

    spec = LPController
    with Node(system.profile, "controller", spec.params, spec.reads, spec.writes) as node:
        controller = LPController(node)
        node.start()
        for publisher in put.values():  # else a first message may go before its subscriber
            matched(publisher)
        held = goal(2.0)
        send(topics.CONTROL_GOAL, held)
        while step().status == "no goal":
            pass  # the goal on its way
        assert step(forward=0.05).status == TELEOP
        send(topics.CONTROL_GOAL, held.model_copy(update={"header": goal(2.0).header}))
        answer = step(forward=0.05)
        assert answer.status == TELEOP and controller.teleoperated  # the same goal: still yields
        while (answer := step()).reason == "":
            pass  # no command: the dead-man timeout
        assert answer.status == TELEOP and "dead-man" in answer.reason
        send(topics.CONTROL_GOAL, goal(2.5))
        while step().status == TELEOP:
            pass  # a new goal: the law again
        assert not controller.teleoperated


def test_the_supervisor_holds_while_stopped_and_yields_to_a_hand_until_a_new_goal(
    deployed,
) -> None:
    """The supervisor process (``tests.components.test_supervisor``'s): while the namespace is
    stopped, and while a hand teleoperates, no goal goes out; a release, and a new goal, bring
    them back (the same goal again does not end the teleoperation)."""
    operator = supervised(deployed)
    namespace = operator.system.profile.namespace
    router = operator.system.router
    goals = met_at(REACH_GOAL)
    first, second = goals["PositionTask"], goals["PointTask"]

    def answered() -> None:
        """A state, and the status answering it (by its stamp: not a timer's status, which
        may come before the state is handled and count no goal for it)."""
        stamp = operator.send_state(HOME)
        operator.statuses.wait_for(lambda s: s.header.stamp_ns == stamp, "the state's status")

    def goals_after_a_state() -> int:
        """Goals out between the statuses answering two states."""
        answered()
        before = len(operator.goals.messages)
        answered()
        return len(operator.goals.messages) - before

    operator.answer_to(operator.send_goal(first), HOME, "the goal taken")
    operator.goals.wait_for(lambda g: g.task == "position", "the goal passed on")
    stop = router.declare_publisher(topics.CONTROL_STOP.key(namespace))
    stop.put(codec.encode(stop_state(True, "test")))
    deadline = time.monotonic() + DEADLINE_S
    while goals_after_a_state():
        assert time.monotonic() < deadline, "goals went on while stopped"
    stop.put(codec.encode(stop_state(False, "test")))
    while not goals_after_a_state():
        assert time.monotonic() < deadline, "no goal after the release"
    hand_out = router.declare_publisher(topics.TELEOP_COMMAND.key(namespace))
    hand_out.put(codec.encode(hand(forward=0.05)))
    while goals_after_a_state():
        assert time.monotonic() < deadline, "goals went on while teleoperated"
    operator.send_goal(first.model_copy(update={"header": header()}))
    assert goals_after_a_state() == 0  # the same goal: still yielding
    operator.answer_to(operator.send_goal(second), HOME, "the goal taken")
    operator.goals.wait_for(lambda g: g.task == "point", "the new goal passed on")


def test_parsimony_teleop_puts_what_the_keys_ask_and_zero_on_its_way_out(deployed) -> None:
    """`parsimony teleop` on a terminal (a pseudo-terminal the test types into)."""
    system = deployed(DEPLOY / "hardware.yaml")
    heard = system.inbox(topics.TELEOP_COMMAND)
    leader, follower = os.openpty()
    command = [sys.executable, "-m", "parsimony.cli", "teleop", "--profile", str(system.path)]
    process = subprocess.Popen(command, stdin=follower, stderr=subprocess.PIPE, text=True)
    try:
        heard.wait_for(lambda c: c.forward == 0.0, "a still command")  # the tool is reading
        os.write(leader, b"w")
        heard.wait_for(lambda c: c.forward == 0.1, "forward")
        os.write(leader, b"2i")
        heard.wait_for(lambda c: c.joint == ROBOT.joint_names[1] and c.joint_velocity == 0.3, "j")
        os.write(leader, b"q")
        assert process.wait(DEADLINE_S) == 0, process.stderr.read() if process.stderr else ""
    finally:
        process.kill()
        os.close(leader)
        os.close(follower)
    last = heard.messages[-1]
    assert (last.forward, last.turn, last.joint_velocity) == (0.0, 0.0, 0.0)
