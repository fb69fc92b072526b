"""The arm driver on protocol 2.0 (``protocol: 2``) as a process against the emulated X-series
chain of the OpenManipulator-X on a pseudo-terminal: the AX driver's tests
(tests/components/test_arm_driver.py) again, on one driver process the tests share, and a
hardware error counted by name."""

from __future__ import annotations

import math
import time
from collections.abc import Iterator

import pytest

from components.servo_bus import HOLD_SPEED
from profiles.deploy_files import DEPLOY
from protocols import x_series_units as x_units
from protocols.dynamixel_v1 import StatusFault
from protocols.dynamixel_v2 import Address
from sim2d.devices.servo_chain import ANSWER_TIMEOUT_S, IntegratingJoints
from sim2d.devices.x_servos import XChainEmulator
from tests.components.arm_bench import ArmBench
from tests.components.conftest import _wait_until
from tests.components.driver_harness import status
from wbc.robot import MobileManipulator
from wbc.servo_map import ServoMap

ROBOT_FILE = DEPLOY / "robots" / "open_manipulator_x.yaml"
ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
IDS = ServoMap.of(ROBOT_FILE, ROBOT.arm_dof).ids
"""The servos' bus ids, joint by joint, as the robot's description gives them."""
LOW, HIGH = ROBOT.q_min[3:], ROBOT.q_max[3:]
START = (0.0, -0.2, 0.2, 0.5)
UNIT = 1.0 / x_units.POSITION_UNITS_PER_RAD


class Bench(ArmBench):
    """The X-series chain: commands naming their joints, Profile Velocity left by a Sync
    Write."""

    speed_address = Address.PROFILE_VELOCITY
    joint_names = ROBOT.joint_names

    def counters(self) -> dict[str, int]:
        return status(self.system, "arm_driver").counters

    def hold_still(self) -> None:
        """Every servo whole and inside its limits again, the arm held (between tests)."""
        for servo in self.servos.servos:
            self.servos.corrupt(servo.id, None)
            if servo.silent:
                self.servos.recover(servo.id)
        _wait_until(lambda: self.state() == "running", "the driver running again")
        self.written((0.0,) * 4)


@pytest.fixture(scope="module")
def shared(deployed_for_module, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Bench]:
    arm = IntegratingJoints(list(START))
    link = tmp_path_factory.mktemp("x_chain") / "servos"
    with XChainEmulator(arm, IDS, link=link) as servos:
        profile = link.parent / "profile.yaml"
        profile.write_text(
            f"extends: {DEPLOY / 'hardware.yaml'}\nrobot: {ROBOT_FILE}\ncomponents:\n"
            f"  - name: arm_driver\n    params: {{port: {link}, protocol: 2, "
            f"answer_timeout_s: {ANSWER_TIMEOUT_S}}}\n"
        )
        system = deployed_for_module(profile)
        yield from Bench(system, arm, servos).serve()


@pytest.fixture
def bench(shared: Bench) -> Iterator[Bench]:
    yield shared
    shared.hold_still()


def test_the_arm_moves_as_commanded_and_a_joint_commanded_to_stop_holds(bench: Bench) -> None:
    first = bench.joints.messages[0]
    assert max(abs(p - s) for p, s in zip(first.positions, START, strict=True)) <= UNIT
    assert bench.servos.words(Address.TORQUE_ENABLE) == [1] * 4
    assert bench.servos.counters["sync_reads"] > 0  # every servo read by one instruction
    q1, q4, q2 = bench.arm.angles[0], bench.arm.angles[3], bench.arm.angles[1]

    def command_and_step() -> bool:
        bench.send((0.3, 0.0, 0.0, -0.3))
        bench.run(0.05)
        time.sleep(0.02)  # the servos' own time passing
        return bench.arm.angles[0] > q1 + 0.2 and bench.arm.angles[3] < q4 - 0.2

    _wait_until(command_and_step, "q1 and q4 moving as commanded")
    assert abs(bench.arm.angles[1] - q2) < 0.01


def test_a_joint_commanded_to_exactly_zero_does_not_creep(bench: Bench) -> None:
    bench.written((0.0,) * 4)
    bench.run(0.5)  # settle on the hold
    start = list(bench.arm.angles)
    for k in range(100):  # 2 s of commands at 50 Hz
        bench.written((0.0, -0.0, 0.0, -0.0) if k % 2 else (-0.0,) * 4)
        bench.run(0.02)
    assert max(abs(a - b) for a, b in zip(bench.arm.angles, start, strict=True)) <= UNIT / 2
    assert bench.speeds() == [HOLD_SPEED] * 4


def test_a_silent_servo_holds_the_whole_arm_until_it_answers_again(bench: Bench) -> None:
    moving = (0.4, 0.3, -0.3, 0.4)
    bench.written(moving)
    asked = bench.servos.counters["unanswered"]
    bench.servos.fail(IDS[2])
    _wait_until(lambda: bench.servos.counters["unanswered"] > asked, "the driver asking servo 3")
    bench.run(0.1)  # while the driver waits for its answer
    _wait_until(lambda: bench.state() == f"holding: servo {IDS[2]} silent", "the arm holding")
    _wait_until(
        lambda: [bench.speeds()[i] for i in (0, 1, 3)] == [HOLD_SPEED] * 3,
        "the hold written to every servo that answers",
    )
    held = list(bench.arm.angles)
    for _ in range(50):  # a second of commands that must not move it
        bench.command_step(moving)
    assert max(abs(a - b) for a, b in zip(bench.arm.angles, held, strict=True)) <= UNIT
    counters = bench.counters()
    assert counters["servo_faults.silent"] >= 1 and counters["refused_commands"] >= 1
    bench.servos.recover(IDS[2])  # torque off, as after a brown-out: the driver enables it again
    _wait_until(lambda: bench.state() == "running", "every servo answering again")
    q1, q3 = bench.arm.angles[0], bench.arm.angles[2]

    def moves_again() -> bool:
        bench.command_step(moving)
        return bench.arm.angles[0] > q1 + 0.05 and bench.arm.angles[2] < q3 - 0.05

    _wait_until(moves_again, "the arm, servo 3 included, moving again")


def test_a_reading_outside_the_limits_is_refused_and_no_goal_leaves_them(bench: Bench) -> None:
    high_units = math.floor(x_units.position_of_angle(HIGH[2]))
    bench.written((0.0, 0.0, 0.8, 0.0))
    assert bench.servos.words(Address.GOAL_POSITION)[2] <= high_units
    inside = bench.arm.angles[2]
    bench.arm.angles[2] = HIGH[2] + 0.3
    _wait_until(
        lambda: bench.state().startswith(f"holding: servo {IDS[2]} reads 1.7"), "the refusal"
    )
    for _ in range(20):
        bench.send((0.0, 0.0, 0.8, 0.0))
        time.sleep(0.02)
    assert bench.servos.words(Address.GOAL_POSITION)[2] <= high_units
    assert all(m.positions[2] <= HIGH[2] + 0.02 for m in bench.joints.messages)
    assert bench.counters()["out_of_limits"] >= 1
    bench.arm.angles[2] = inside


def test_speeds_over_the_limit_go_out_at_the_limit(bench: Bench) -> None:
    written: list[int] = []

    def commanded() -> bool:
        bench.send((1e3, 1e300, -1e308, 0.5))
        time.sleep(0.005)
        written[:] = bench.speeds()
        return written not in ([0] * 4, [HOLD_SPEED] * 4)

    _wait_until(commanded, "a Sync Write of the command")
    limit = x_units.profile_velocity(ROBOT.velocity_max[3])
    assert written == [limit] * 3 + [x_units.profile_velocity(0.5)]
    counters = bench.counters()
    assert counters["speed_limited"] >= 3
    assert not any(v for k, v in counters.items() if k.startswith("errors."))


@pytest.mark.parametrize(
    "fault",
    [StatusFault.TRUNCATED, StatusFault.CHECKSUM, StatusFault.WRONG_ID, StatusFault.WRONG_LENGTH],
)
def test_a_spoiled_status_packet_is_reported_by_its_name(bench: Bench, fault: StatusFault) -> None:
    bench.servos.corrupt(IDS[1], fault)
    _wait_until(lambda: bench.state() == f"holding: servo {IDS[1]} {fault}", f"servo 2 {fault}")
    assert bench.counters()[f"servo_faults.{fault}"] >= 1
    bench.servos.corrupt(IDS[1], None)
    _wait_until(lambda: bench.state() == "running", "servo 2 answering whole again")


def test_a_hardware_error_is_counted_by_name(bench: Bench) -> None:
    """An overload: the alert bit in every answer, Hardware Error Status read and counted."""
    bench.servos.fail(IDS[3], silent=False)
    _wait_until(lambda: bench.counters()["servo_error.overload"] >= 1, "the overload counted")
    assert bench.counters()["servo_error.input_voltage"] == 0
    bench.servos.servos[3].table[Address.HARDWARE_ERROR_STATUS] = 0  # a reboot, by hand
