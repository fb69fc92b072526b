"""The arm driver's protocol 2.0 bus (components/servo_bus.py) on the emulated X-series chain
through a real pty: torque comes on in position mode with the goal where the servo is, and a
Sync Read gives every servo's reading or none."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from components.servo_bus import BUSES, XBus, open_port
from protocols import dynamixel_v2 as dxl
from protocols import x_series_units as x_units
from protocols.dynamixel_v2 import Address, OperatingMode
from sim2d.devices.ax_servos import AXChainEmulator
from sim2d.devices.servo_chain import ANSWER_TIMEOUT_S, IntegratingJoints
from sim2d.devices.x_servos import XChainEmulator

START = (0.0, 0.4, -0.6)


@pytest.fixture
def chain() -> Iterator[tuple[XChainEmulator, IntegratingJoints, XBus]]:
    arm = IntegratingJoints(START)
    with XChainEmulator(arm) as emulator:
        bus = XBus(emulator.port, ANSWER_TIMEOUT_S)
        assert open_port(bus.port, 1_000_000)
        yield emulator, arm, bus
        bus.port.closePort()


def test_torque_comes_on_in_position_mode_with_the_goal_where_the_servo_is(chain) -> None:
    """A servo left in velocity mode with a stale goal far away: the goal would have thrown
    the joint there the moment torque came on."""
    emulator, arm, bus = chain
    servo = emulator.servos[1]
    servo.table[Address.OPERATING_MODE] = OperatingMode.VELOCITY
    servo.table[Address.GOAL_POSITION : Address.GOAL_POSITION + 4] = dxl.value(4000, 4)
    assert bus.enable_torque(2) == 0
    assert servo.table[Address.OPERATING_MODE] == OperatingMode.POSITION
    assert servo.table[Address.TORQUE_ENABLE] == 1
    assert servo.word(Address.GOAL_POSITION) == x_units.position_units(START[1])
    for _ in range(50):
        emulator.update(0.01)
        arm.step(0.01)
    assert abs(arm.angles[1] - START[1]) <= 1.0 / x_units.POSITION_UNITS_PER_RAD


def test_a_sync_read_gives_every_reading_or_none(chain) -> None:
    emulator, arm, bus = chain
    readings = bus.read_all((1, 2, 3))
    assert readings is not None
    assert [units for (units, _), _, _ in readings] == [x_units.position_units(a) for a in START]
    emulator.fail(2)
    assert bus.read_all((1, 2, 3)) is None  # read one at a time, to name servo 2's fault
    assert bus.read(3)[1] is None


LATE_S = 0.1
"""How late the stalled chain answers: more than the SDK's own timeout (34 ms), far less than
the bus's answer timeout."""


@pytest.mark.parametrize("protocol", [1, 2])
def test_a_late_answer_is_an_answer_on_every_exchange(protocol: int) -> None:
    """A chain starved past the SDK's packet timeout answers a torque enable (the SDK's own
    exchange) and a read late: each is an answer, for the bus awaits its answer timeout
    whichever call asks. (Before, a torque enable kept the SDK's 34 ms and came back None.)"""
    chain_type = {1: AXChainEmulator, 2: XChainEmulator}[protocol]
    with chain_type(IntegratingJoints(START)) as emulator:
        bus = BUSES[protocol](emulator.port, ANSWER_TIMEOUT_S)
        assert open_port(bus.port, 1_000_000)
        emulator.stall(LATE_S)
        assert bus.enable_torque(2) == 0
        emulator.stall(LATE_S)
        assert bus.read(3)[1] is None
        if protocol == 2:
            emulator.stall(LATE_S)
            assert bus.read_all((1, 2, 3)) is not None
        bus.port.closePort()
