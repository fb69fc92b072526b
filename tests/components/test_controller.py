"""The LP and cascade controllers as processes, on real Zenoh sessions over loopback.

The test plays the estimator and the operator: it publishes states and goals on the
profile's router and reads what the controller answers. Every command and diagnostics
message carries the stamp of the state it answers, so each answer is found by its stamp.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import msgpack
import numpy as np
import pytest
import yaml
import zenoh

from components.lp_controller import LPController
from components.runtime import Node
from launch import query
from messages import codec, topics
from messages.commands import ArmCommand, BaseCommand
from messages.diagnostics import ControllerDiagnostics
from messages.goal import Goal
from messages.header import Header
from messages.state import RobotState
from parsimony.commands import param
from profiles.deploy_files import DEPLOY, ROBOT_FILE
from profiles.profile import load_profile
from wbc.geometry.scenarios import NEAR_START, REACH_GOAL
from wbc.robot import MobileManipulator

if TYPE_CHECKING:
    from tests.components.conftest import System

LP_PROFILE = DEPLOY / "controllers.yaml"
CASCADE_PROFILE = DEPLOY / "controllers_cascade.yaml"

DEADLINE_S = 60.0
"""Generous limit for anything that involves starting a process on a loaded machine."""

START = tuple(NEAR_START.tolist())
"""The configuration the states report: [x, y, phi, q1..q5]."""

GOAL_Q = tuple(REACH_GOAL.tolist())
"""The configuration whose end-effector pose is the profile's goal."""

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
GOAL_POSE = tuple(ROBOT.fkm(np.array(GOAL_Q)).tolist())

STALE_TIMEOUT_S = 0.5
"""The controller's ``stale_timeout_s`` in the profile."""


class Operator:
    """The test's side of a controller: states and goals out, commands and diagnostics in."""

    def __init__(self, system: System) -> None:
        self.system = system
        namespace = system.profile.namespace
        session = system.router
        self.namespace = namespace
        self.state_key = topics.ROBOT_STATE.key(namespace)
        block = zenoh.CongestionControl.BLOCK  # the tests count every message: none dropped
        self.state = session.declare_publisher(self.state_key, congestion_control=block)
        self.goal = session.declare_publisher(
            topics.CONTROL_GOAL.key(namespace), congestion_control=block
        )
        self.base = system.inbox(topics.BASE_COMMAND)
        self.arm = system.inbox(topics.ARM_COMMAND)
        self.diagnostics = system.inbox(topics.CONTROL_DIAGNOSTICS)
        self._stamps: set[int] = set()

    def wait_connected(self) -> None:
        """Wait until the controller is alive (answers queries) and subscribes to its inputs."""
        self.system.liveliness().wait_for("controller", alive=True)
        deadline = time.monotonic() + DEADLINE_S
        while not (self.state.matching_status.matching and self.goal.matching_status.matching):
            assert time.monotonic() < deadline, "the controller did not subscribe in time"
            time.sleep(0.005)

    def stamp(self, age_s: float = 0.0) -> int:
        """A fresh stamp, ``age_s`` in the past, distinct from every earlier one."""
        stamp = time.time_ns() - round(age_s * 1e9)
        while stamp in self._stamps:
            stamp += 1
        self._stamps.add(stamp)
        return stamp

    def send_state(
        self,
        valid: bool = True,
        age_s: float = 0.0,
        base_pose: tuple[float, float, float] = START[:3],
    ) -> int:
        """Publish a state at ``START`` (or its arm at ``base_pose``); return its stamp."""
        stamp = self.stamp(age_s)
        state = RobotState(
            header=Header(stamp_ns=stamp, frame="world", seq=0, source="test"),
            base_pose=base_pose,
            arm_joints=START[3:],
            end_effector=GOAL_POSE,
            valid=valid,
            age_s=0.0,
        )
        self.state.put(codec.encode(state))
        return stamp

    def send_goal(self, eta: float | None = None, beta: float | None = None) -> None:
        """Publish a pose goal and wait until the controller has taken it.

        (Zenoh calls each subscription's handler on its own thread: a goal published
        before a state may still be handled after it.)
        """
        taken = self.counters()["received.control/goal"]
        self.put_goal(eta, beta)
        deadline = time.monotonic() + DEADLINE_S
        while self.counters()["received.control/goal"] == taken:
            assert time.monotonic() < deadline, "the controller did not take the goal"

    def put_goal(self, eta: float | None = None, beta: float | None = None) -> None:
        """Publish a pose goal with these gains."""
        header = Header(stamp_ns=self.stamp(), frame="world", seq=0, source="test")
        goal = Goal(header=header, task="pose", pose=GOAL_POSE, eta=eta, beta=beta)
        self.goal.put(codec.encode(goal))

    def answer(self, stamp: int) -> tuple[ControllerDiagnostics, BaseCommand, ArmCommand]:
        """The diagnostics and commands that answer the state stamped ``stamp``."""
        what = f"stamped {stamp}"
        return (
            self.diagnostics.wait_for(lambda m: m.header.stamp_ns == stamp, what),
            self.base.wait_for(lambda m: m.header.stamp_ns == stamp, what),
            self.arm.wait_for(lambda m: m.header.stamp_ns == stamp, what),
        )

    def step(self, valid: bool = True, age_s: float = 0.0) -> tuple[ControllerDiagnostics, ...]:
        """Publish a state and wait for the controller's answer."""
        return self.answer(self.send_state(valid, age_s))

    def counters(self) -> dict[str, int]:
        """The controller's counters, from its status queryable."""
        return query.statuses(self.system.router, self.namespace)["controller"].counters

    def assert_every_command_finite(self) -> None:
        assert self.base.undecodable == self.arm.undecodable == []
        assert self.diagnostics.undecodable == []
        for command in self.base.messages:
            wheels = command.left_wheel, command.right_wheel, command.forward_velocity
            assert all(math.isfinite(v) for v in (*wheels, command.angular_velocity))
        for command in self.arm.messages:
            assert all(math.isfinite(v) for v in command.joint_velocities)


def is_zero(base: BaseCommand, arm: ArmCommand) -> bool:
    wheels = (base.forward_velocity, base.angular_velocity, base.left_wheel, base.right_wheel)
    return wheels == (0.0,) * 4 and arm.joint_velocities == (0.0,) * 5


@pytest.fixture(scope="module")
def controller(deployed_for_module: Callable[[str], System]) -> System:
    """The LP profile's controller alone, one process for the tests that do not need it new."""
    system = deployed_for_module(LP_PROFILE.read_text())
    system.start("controller")
    return system


@pytest.fixture
def operator(controller: System) -> Iterator[Operator]:
    """A new operator of the module's controller, subscribed; the controller's ``eta`` is
    the profile's again after the test (a test sets it)."""
    operator = Operator(controller)
    operator.wait_connected()
    yield operator
    eta = controller.profile.component("controller").params["eta"]
    query.set_param(controller.router, operator.namespace, "controller", "eta", str(eta))


@pytest.fixture
def new_operator(deployed: Callable[[str], System]) -> Operator:
    """The LP profile's controller alone, a process of its own, started and subscribed."""
    system = deployed(LP_PROFILE.read_text())
    system.start("controller")
    operator = Operator(system)
    operator.wait_connected()
    return operator


def test_the_cascade_profile_is_the_lp_profile_with_another_module() -> None:
    lp, cascade = load_profile(LP_PROFILE), load_profile(CASCADE_PROFILE)
    assert lp.component("controller").module == "lp_controller"
    swapped = [
        spec.model_copy(update={"module": "cascade_controller"})
        if spec.name == "controller"
        else spec
        for spec in lp.components
    ]
    assert cascade == lp.model_copy(update={"components": swapped})


def test_the_profile_starts_inside_the_joint_limits_with_the_pose_of_goal_q_as_goal() -> None:
    params = yaml.safe_load(LP_PROFILE.read_text())["components"][0]["params"]
    names = ("base_x", "base_y", "base_phi", "q1", "q2", "q3", "q4", "q5")
    assert tuple(params[name] for name in names) == START
    assert np.all(ROBOT.q_min < START) and np.all(np.array(START) < ROBOT.q_max)
    assert np.all(ROBOT.q_min < GOAL_Q) and np.all(np.array(GOAL_Q) < ROBOT.q_max)
    np.testing.assert_allclose(params["goal_pose"], GOAL_POSE, atol=1e-12)


@pytest.mark.parametrize(("profile", "law"), [(LP_PROFILE, "lp"), (CASCADE_PROFILE, "cascade")])
def test_a_profile_with_a_scripted_state_and_goal_makes_finite_optimal_commands(
    deployed: Callable[[str | Path], System], profile: Path, law: str
) -> None:
    system = deployed(profile)
    operator = Operator(system)
    system.start("controller")
    system.start("publisher")
    diagnostics = operator.diagnostics.wait_for(lambda m: m.status == "optimal", "optimal")
    _, base, arm = operator.answer(diagnostics.header.stamp_ns)
    assert diagnostics.law == law and diagnostics.reason == ""
    assert diagnostics.error_norm is not None and diagnostics.error_norm > 0.1
    assert diagnostics.parameters["eta"] == 0.6
    assert abs(base.left_wheel) <= 0.5 and abs(base.right_wheel) <= 0.5
    assert base.header.source == arm.header.source == "controller"
    operator.assert_every_command_finite()


def test_malformed_states_are_counted_and_never_reach_a_motor(operator: Operator) -> None:
    operator.send_goal()
    assert operator.step()[0].status == "optimal"
    header = Header(stamp_ns=operator.stamp(), frame="world", seq=0, source="test")
    goal = Goal(header=header, task="position", position=(0.5, 0.0, 0.3))
    nan_state = {
        "header": {"stamp_ns": operator.stamp(), "frame": "world", "seq": 0, "source": "test"},
        "base_pose": (math.nan, 0.0, 0.0),
        "arm_joints": START[3:],
        "end_effector": GOAL_POSE,
        "valid": True,
        "age_s": 0.0,
    }
    malformed = (
        b"\x00garbage\xff",
        codec.encode(goal),
        msgpack.packb([codec.FORMAT_TAG, "RobotState", nan_state], use_bin_type=True),
    )
    rejected = operator.counters()["rejected.robot/state"]
    for count, payload in enumerate(malformed, start=1):
        operator.state.put(payload)
        deadline = time.monotonic() + DEADLINE_S
        while operator.counters()["rejected.robot/state"] < rejected + count:
            assert time.monotonic() < deadline, f"malformed state {count} was not rejected"
    diagnostics, _, _ = operator.step()
    assert diagnostics.status == "optimal"
    counters = operator.counters()
    assert counters["rejected.robot/state"] >= rejected + 3
    assert counters["errors.robot/state"] == counters["non_finite_commands"] == 0
    assert operator.system.processes[0].poll() is None
    operator.assert_every_command_finite()


def test_no_state_no_goal_an_invalid_and_an_old_state_command_zero_and_say_why(
    new_operator: Operator,
) -> None:
    operator = new_operator
    before = operator.diagnostics.wait_for(lambda m: m.status == "stale", "before any state")
    assert before.reason == "no robot/state received yet"
    assert is_zero(*operator.answer(before.header.stamp_ns)[1:])

    diagnostics, base, arm = operator.step()
    assert (diagnostics.status, diagnostics.reason) == ("no goal", "no control/goal received yet")
    assert is_zero(base, arm)

    operator.send_goal()
    diagnostics, base, arm = operator.step()
    assert diagnostics.status == "optimal" and not is_zero(base, arm)

    diagnostics, base, arm = operator.step(valid=False)
    assert diagnostics.status == "invalid state" and is_zero(base, arm)

    diagnostics, base, arm = operator.step(age_s=2.0)
    assert diagnostics.status == "stale" and is_zero(base, arm)
    assert diagnostics.reason.startswith("robot/state is 2.0")
    assert diagnostics.reason.endswith(f"s old (timeout {STALE_TIMEOUT_S} s)")
    operator.assert_every_command_finite()


def test_states_that_stop_arriving_command_zero_once_the_timeout_has_passed(
    operator: Operator,
) -> None:
    """Judged by stamps on the controller's clock (the host's), not by how soon the stale comes:
    a stale computed before this state was handled (the last test's state aging) is stamped
    within the timeout of it, and is not the one awaited."""
    operator.send_goal()
    last = operator.send_state()
    assert operator.answer(last)[0].status == "optimal"
    timeout_ns = round(STALE_TIMEOUT_S * 1e9)
    stale = operator.diagnostics.wait_for(
        lambda m: m.header.stamp_ns >= last + timeout_ns and m.status == "stale",
        "stale the timeout after the last state",
    )
    assert stale.reason.startswith("no robot/state for")
    assert float(stale.reason.split()[3]) >= STALE_TIMEOUT_S, stale.reason
    _, base, arm = operator.answer(stale.header.stamp_ns)
    assert is_zero(base, arm)


def set_param(operator: Operator, name: str, value: str) -> int:
    """`parsimony param set controller NAME VALUE --profile P` through its own parser."""
    root = argparse.ArgumentParser(prog="parsimony")
    param.add_parser(root.add_subparsers())
    argv = ["param", "set", "controller", name, value, "--profile", str(operator.system.path)]
    return param.run(root.parse_args(argv))


def test_param_set_and_goal_gains_reach_the_next_step(
    operator: Operator, capsys: pytest.CaptureFixture[str]
) -> None:
    operator.send_goal()
    assert operator.step()[0].parameters["eta"] == 0.6
    assert set_param(operator, "eta", "2.0") == 0
    assert capsys.readouterr().out.strip() == "controller.eta = 2.0"
    diagnostics = operator.step()[0]
    assert diagnostics.status == "optimal" and diagnostics.parameters["eta"] == 2.0

    operator.send_goal(eta=1.5)
    assert operator.step()[0].parameters["eta"] == 1.5
    assert set_param(operator, "eta", "-1") == 1
    assert "eta: expected a float in [0.001, 100.0]" in capsys.readouterr().err


def test_a_robot_parameter_that_cannot_load_is_refused_and_the_controller_goes_on(
    operator: Operator, capsys: pytest.CaptureFixture[str]
) -> None:
    operator.send_goal()
    assert operator.step()[0].status == "optimal"
    assert set_param(operator, "robot", "/etc/passwd") == 1
    assert "robot: cannot load /etc/passwd" in capsys.readouterr().err
    assert operator.step()[0].status == "optimal"


def test_a_goal_whose_gains_leave_the_parameter_bounds_is_refused(operator: Operator) -> None:
    """eta = 1e300 on a goal is checked like `param set`: refused, counted, zero commands, and
    the diagnostics say which gain and its bounds."""
    operator.send_goal()
    assert operator.step()[0].status == "optimal"
    refused = operator.counters()["refused_goals"]
    operator.send_goal(eta=1e300)
    diagnostics, base, arm = operator.step()
    assert diagnostics.status == "goal refused" and is_zero(base, arm), diagnostics
    assert diagnostics.reason.startswith(
        "control/goal refused: eta: expected a float in [0.001, 100.0], got 1e+300"
    ), diagnostics.reason
    assert operator.counters()["refused_goals"] == refused + 1
    operator.send_goal(eta=1.5)
    assert operator.step()[0].parameters["eta"] == 1.5


def test_obstacles_with_a_solid_larger_than_a_scene_are_refused_in_one_line(
    operator: Operator,
) -> None:
    """A cylinder of radius 1e300 on world/obstacles, as bytes a sender's own check let through:
    the message's schema refuses it (``rejected.world/obstacles``) in one line naming the
    field, no traceback, and the controller steps on."""
    from messages.obstacles import Cylinder, Obstacles, Solids

    operator.send_goal()
    obstacles = operator.system.router.declare_publisher(
        topics.WORLD_OBSTACLES.key(operator.namespace)
    )
    header = Header(stamp_ns=operator.stamp(), frame="world", seq=0, source="test")
    pole = Solids(cylinders=(Cylinder(x=3.0, y=0.0, radius=0.1),))
    tag, name, fields = msgpack.unpackb(codec.encode(Obstacles(header=header, solids=pole)))
    fields["solids"]["cylinders"][0]["radius"] = 1e300
    rejected = operator.counters()["rejected.world/obstacles"]
    obstacles.put(msgpack.packb([tag, name, fields], use_bin_type=True))
    deadline = time.monotonic() + DEADLINE_S
    while operator.counters()["rejected.world/obstacles"] < rejected + 1:
        assert time.monotonic() < deadline, "the obstacles were not refused"
    assert operator.step()[0].status == "optimal"
    log = operator.system.log("controller")
    assert "expected a number > 0 and <= 100 m" in log, log
    assert "Traceback" not in log and operator.counters()["errors.world/obstacles"] == 0


FAR = (1e300, -1e300, 1e300)
"""A base pose whose program overflows (the QP law's u was all NaN, reported optimal)."""
FLOOD = 200
"""Messages of each kind in a flood."""


@pytest.mark.parametrize("module", ["lp_controller", "qp_controller", "cascade_controller"])
def test_a_flood_of_states_far_away_and_of_goals_out_of_bounds_is_answered_without_a_traceback(
    deployed: Callable[[str], System], module: str
) -> None:
    """States at (1e300, -1e300, 1e300), then goals with eta or beta of 1e300 or 1e-300: every
    state handled is answered (the QP's NaN raised in ``wheel_speeds``: nothing was published
    for it), by a finite command, zero unless optimal; every goal is refused in one line naming
    the gain and its bounds; no traceback; the controller then follows a good goal again."""
    system = deployed(LP_PROFILE.read_text().replace("lp_controller", module))
    system.start("controller")
    operator = Operator(system)
    operator.wait_connected()
    operator.send_goal()
    stamps = [operator.send_state(base_pose=FAR) for _ in range(FLOOD)]
    operator.answer(stamps[-1])  # the newest state is always handled, and answered last
    counters = operator.counters()
    answered = [m for m in operator.diagnostics.messages if m.header.stamp_ns in set(stamps)]
    assert len(answered) == counters["received.robot/state"] >= 1
    assert counters["received.robot/state"] + counters["overwritten.robot/state"] == FLOOD
    for diagnostics in answered:
        _, base, arm = operator.answer(diagnostics.header.stamp_ns)
        assert diagnostics.status == "optimal" or is_zero(base, arm), diagnostics
        assert diagnostics.status == "non-finite" or module != "qp_controller", diagnostics

    gains = [("eta", 1e300), ("beta", 1e-300), ("beta", 1e300), ("eta", 1e-300)]
    taken = counters["received.control/goal"] + counters["overwritten.control/goal"]
    for index in range(FLOOD):
        name, value = gains[index % len(gains)]
        operator.put_goal(**{name: value})
    deadline = time.monotonic() + DEADLINE_S
    while (
        sum(operator.counters()[f"{kind}.control/goal"] for kind in ("received", "overwritten"))
        < taken + FLOOD
    ):
        assert time.monotonic() < deadline, "the controller did not take every goal"
    diagnostics, base, arm = operator.step()  # the last goal sent: eta 1e-300
    assert diagnostics.status == "goal refused" and is_zero(base, arm), diagnostics
    assert "eta: expected a float in [0.001, 100.0], got 1e-300" in diagnostics.reason
    counters = operator.counters()
    assert counters["refused_goals"] >= 1
    assert counters["errors.robot/state"] == counters["errors.control/goal"] == 0
    assert "Traceback" not in system.log("controller")

    operator.send_goal()
    assert operator.step()[0].status == "optimal"
    assert system.processes[0].poll() is None
    operator.assert_every_command_finite()


def test_a_robot_description_that_cannot_be_loaded_is_a_configuration_error(
    deployed: Callable[[str], System],
) -> None:
    text = LP_PROFILE.read_text().replace("eta: 0.6", "robot: /nonexistent/robot.yaml")
    system = deployed(text)
    process = system.start("controller")
    assert process.wait(DEADLINE_S) == 2
    assert "robot: cannot load /nonexistent/robot.yaml" in system.log("controller")


def test_the_law_gets_changed_gains_and_only_then(deployed: Callable[[str], System]) -> None:
    """Gains are computed again after a parameter or goal change, and reach the law."""
    system = deployed(LP_PROFILE.read_text())
    with Node(system.profile, "controller", LPController.params) as node:
        controller = LPController(node)
        law = controller.stepper.law
        gains = controller.stepper.gains
        controller.update_law()
        assert controller.stepper.gains is gains and law.params.eta == 0.6

        node.params.set_text("eta", "2.0")
        controller.update_law()
        assert controller.stepper.law is law and law.params.eta == 2.0
        assert controller.stepper.gains.eta == 2.0

        header = Header(stamp_ns=1, frame="world", seq=0, source="test")
        controller.on_goal(Goal(header=header, task="pose", pose=GOAL_POSE, eta=1.5))
        controller.update_law()
        assert law.params.eta == 1.5 and controller.stepper.gains.eta == 1.5
        node.params.set_text("joint_gain", "3.0")
        controller.update_law()
        assert (law.params.eta, law.params.joint_gain) == (1.5, 3.0)


def test_on_simulated_time_a_stopped_clock_makes_the_controller_command_zero(
    deployed: Callable[[str | Path], System], wait_until: Callable[..., None]
) -> None:
    text = LP_PROFILE.read_text().replace(
        "namespace: parsimony", "namespace: parsimony\nclock: sim\nclock_timeout_s: 0.3"
    )
    system = deployed(text)
    diagnostics = system.inbox(topics.CONTROL_DIAGNOSTICS)
    system.start("controller")
    clock = system.router.declare_publisher(topics.SIM_CLOCK.key("parsimony"))
    wait_until(lambda: clock.matching_status.matching, "the controller's clock subscription")
    for tick in range(1, 11):  # one simulated second, then the simulator stops
        clock.put(codec.encode(topics.SIM_CLOCK.type(stamp_ns=tick * 100_000_000)))
    stalled = diagnostics.wait_for(lambda m: "sim/clock has not moved" in m.reason, "stall")
    assert stalled.status == "stale"


def test_a_flood_of_huge_obstacle_messages_never_silences_the_controller(
    operator: Operator,
) -> None:
    """10 MB payloads, and a valid message of 100,000 circles, arrive on world/obstacles for
    2 s: each is refused on arrival, counted, and the stale timer keeps commanding zero with
    no gap longer than the stale timeout (0.5 s)."""
    from messages.obstacles import Circle as CircleMessage
    from messages.obstacles import Obstacles

    obstacles = operator.system.router.declare_publisher(  # every message arrives: none dropped
        topics.WORLD_OBSTACLES.key(operator.namespace),
        congestion_control=zenoh.CongestionControl.BLOCK,
    )
    header = Header(stamp_ns=operator.stamp(), frame="world", seq=0, source="test")
    circles = (CircleMessage(x=1.0, y=0.0, radius=0.1),) * 100_000
    many = codec.encode(Obstacles.model_construct(header=header, circles=circles))
    huge = b"\x93" + bytes(10_000_000)
    before = operator.counters()
    flood_start = time.time_ns()
    sent = 0
    while time.time_ns() - flood_start < 2_000_000_000:
        obstacles.put(huge if sent % 2 else many)
        sent += 1
    flood_end = time.time_ns()
    stamps = sorted(
        m.header.stamp_ns
        for m in operator.diagnostics.messages
        if flood_start <= m.header.stamp_ns <= flood_end
    )
    gaps = np.diff([flood_start, *stamps, flood_end]) / 1e9
    assert gaps.max() <= 0.5, f"silent for {gaps.max():.2f} s during the flood"
    assert all(m.status == "stale" for m in operator.diagnostics.messages)
    deadline = time.monotonic() + DEADLINE_S
    while (
        operator.counters()["rejected.world/obstacles"]
        < before["rejected.world/obstacles"] + sent // 2
    ):
        assert time.monotonic() < deadline, operator.counters()
    assert operator.counters()["received.world/obstacles"] == before["received.world/obstacles"]
