"""The simulator process (real Zenoh, the test as its controller): in lockstep simulated time
waits for the commands of each step, the ground truth follows the commanded wheel speeds as a
differential drive does, and the wheel odometry it publishes agrees with the truth; a start
inside a solid of its scene is warned of, one line per solid naming it and saying what the
robot will do (wbc.geometry.start_inside), and a clear start says nothing of it."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import pytest
import yaml

from messages import codec, topics
from messages.clock import Clock
from messages.commands import ArmCommand, BaseCommand
from messages.header import Header
from messages.odometry import BaseOdometry
from messages.truth import SimTruth
from profiles.deploy_files import DEPLOY
from wbc.geometry.start_inside import CONSEQUENCE
from wbc.robot import MobileManipulator

if TYPE_CHECKING:
    from tests.components.conftest import System

STEP_S = 0.02
STEP_NS = round(STEP_S * 1e9)
SPEED = 0.2
"""The wheels' speed, m/s: within the robot's limit, reached in 0.2 s at 1 m/s^2."""
DEADLINE_S = 30.0
SLAB = {"name": "slab", "normal": [0, 0, 1], "offset": 0.3}
"""Everything below 0.3 m, wherever F0 lies: the base of any start is inside it."""
POLE = {"name": "pole", "x": 5.0, "y": 5.0, "radius": 0.05, "height": 1.0}
"""Far from the start."""


def lockstep_sim() -> str:
    """deploy/sim.yaml with the simulator alone, in lockstep, as fast as it can, no camera,
    held until the test lets it go."""
    data = yaml.safe_load((DEPLOY / "sim.yaml").read_text())
    (simulator,) = [c for c in data["components"] if c["name"] == "simulator"]
    simulator["params"] = {
        "step_s": STEP_S,
        "real_time_factor": 0.0,
        "lockstep": True,
        "ack_timeout_s": 60.0,  # a missed answer fails the test rather than being skipped
        "camera": False,
        "paused": True,
    }
    data["components"] = [simulator]
    return yaml.safe_dump(data, sort_keys=False)


class Controller:
    """The test in the controller's place: it answers the sensors of each step with commands
    stamped as they are, and checks that no clock tick runs ahead of its answers."""

    def __init__(self, system: System) -> None:
        self.system = system
        self.wheel_base = MobileManipulator.from_yaml(system.profile.robot).base.wheel_base
        namespace = system.profile.namespace
        self.base = system.router.declare_publisher(topics.BASE_COMMAND.key(namespace))
        self.arm = system.router.declare_publisher(topics.ARM_COMMAND.key(namespace))
        self.truths = system.inbox(topics.SIM_TRUTH)
        self.odometry = system.inbox(topics.BASE_ODOMETRY)
        self.answered_ns = 0
        self.ahead: list[tuple[int, int]] = []
        """(clock stamp, last stamp answered) of every tick more than a step past an answer."""
        self.paused_ticks = threading.Event()
        self._lock = threading.Lock()
        self._clock = system.router.declare_subscriber(
            topics.SIM_CLOCK.key(namespace), self._on_clock
        )

    def _on_clock(self, sample) -> None:
        tick = codec.decode(sample.payload.to_bytes(), Clock)
        if tick.paused:
            self.paused_ticks.set()
            return
        with self._lock:
            if tick.stamp_ns > self.answered_ns + STEP_NS:
                self.ahead.append((tick.stamp_ns, self.answered_ns))

    def start(self) -> None:
        """Once the simulator hears the commands and is heard, set ``paused`` false."""
        deadline = time.monotonic() + DEADLINE_S
        while not (self.base.matching_status.matching and self.arm.matching_status.matching):
            assert time.monotonic() < deadline, "the simulator did not subscribe in time"
            time.sleep(0.005)
        assert self.paused_ticks.wait(DEADLINE_S), "no paused clock from the simulator"
        namespace = self.system.profile.namespace
        key = topics.param_key(namespace, "simulator", "paused")
        replies = list(self.system.router.get(key, payload="false", timeout=DEADLINE_S))
        assert replies and replies[0].ok is not None, replies

    def answer(self, left: float, right: float) -> SimTruth:
        """Wait for the truth of the next step; answer it with these wheel speeds."""
        after = self.answered_ns
        truth = self.truths.wait_for(lambda t: t.header.stamp_ns > after, "of the next step")
        stamp = truth.header.stamp_ns
        assert stamp == after + STEP_NS, (stamp, after)  # one step, none skipped
        header = Header(stamp_ns=stamp, frame="base", seq=0, source="test")
        base = BaseCommand(
            header=header,
            forward_velocity=0.5 * (left + right),
            angular_velocity=(right - left) / self.wheel_base,
            left_wheel=left,
            right_wheel=right,
        )
        arm = ArmCommand(header=header, joint_velocities=(0.0,) * 5)  # Little John
        with self._lock:
            self.answered_ns = stamp
        self.base.put(codec.encode(base))
        self.arm.put(codec.encode(arm))
        return truth


@pytest.fixture
def controller(deployed: Callable[[str], System]) -> Controller:
    system = deployed(lockstep_sim())
    controller = Controller(system)
    system.start("simulator")
    controller.start()
    return controller


def rate(truths: list[SimTruth], index: int) -> float:
    """The rate of change of base_pose[index] over ``truths``, per simulated second."""
    first, last = truths[0], truths[-1]
    span_s = (last.header.stamp_ns - first.header.stamp_ns) / 1e9
    return (last.base_pose[index] - first.base_pose[index]) / span_s


def test_in_lockstep_time_waits_for_the_commands_and_the_truth_drives_as_commanded(
    controller: Controller,
) -> None:
    # Straight ahead: after the ramp (0.2 s at the acceleration limit), x grows at the speed.
    straight = [controller.answer(SPEED, SPEED) for _ in range(60)]
    assert rate(straight[20:], 0) == pytest.approx(SPEED, rel=0.02)
    _, y, phi = straight[-1].base_pose
    assert abs(y) < 1e-3 and abs(phi) < 1e-3
    # On the spot: the heading turns at (right - left) / wheel base, the base stays put.
    turning = [controller.answer(-SPEED / 2, SPEED / 2) for _ in range(60)]
    assert rate(turning[25:], 2) == pytest.approx(SPEED / controller.wheel_base, rel=0.02)
    assert math.dist(turning[-1].base_pose[:2], turning[25].base_pose[:2]) < 1e-3
    # Not one tick ran more than a step past the test's last answer.
    assert controller.ahead == []


def test_the_wheel_odometry_agrees_with_the_truth(controller: Controller) -> None:
    for k in range(80):
        truth = controller.answer(SPEED if k < 30 else SPEED / 2, SPEED)  # straight, an arc
    odometry = controller.odometry.wait_for(
        lambda o: o.header.stamp_ns == truth.header.stamp_ns, "of the last step"
    )
    assert isinstance(odometry, BaseOdometry)
    assert truth.base_pose[1] > 0.01  # the arc turned left
    assert math.dist((odometry.x, odometry.y), truth.base_pose[:2]) < 0.005
    assert odometry.phi == pytest.approx(truth.base_pose[2], abs=0.01)


def sim_with(arm_obstacles: dict) -> str:
    """deploy/sim.yaml's text with these solids in its scene."""
    data = yaml.safe_load((DEPLOY / "sim.yaml").read_text())
    data["scene"]["arm_obstacles"] = arm_obstacles
    return yaml.safe_dump(data, sort_keys=False)


@pytest.mark.parametrize("planes", [[SLAB], []], ids=["through the robot", "clear"])
def test_a_start_inside_a_solid_is_warned_of_in_one_line_naming_it(
    deployed: Callable[[str], System], planes: list
) -> None:
    system = deployed(sim_with({"planes": planes, "cylinders": [POLE]}))
    liveliness = system.liveliness()
    system.start("simulator")
    liveliness.wait_for("simulator", alive=True)  # warned while it starts, before it is alive
    lines = [
        line for line in system.log("simulator").splitlines() if "the robot starts inside" in line
    ]
    if not planes:
        assert lines == []
        return
    assert len(lines) == 1, lines
    assert "the robot starts inside 'slab' (scene.arm_obstacles.planes[0]): its base" in lines[0]
    assert lines[0].endswith(CONSEQUENCE)
