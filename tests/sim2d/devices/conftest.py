"""The fixtures of the emulated servo chains' tests, whatever their protocol. A test module
declares ``CHAIN`` (the emulator's class), ``IDS``, ``START_ANGLES``, ``PROTOCOL`` (the SDK's
1.0 or 2.0) and, when its port is set to a baud rate, ``BAUD``."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
import serial
from dynamixel_sdk import PacketHandler, PortHandler

from sim2d.devices.servo_chain import IntegratingJoints, ServoChain
from tests.sim2d.devices.patient_port import PatientPort

DT = 0.01
"""The world's and the servos' step, s."""
QUIET_S = 0.03
"""How long the line stays quiet before an exchange is taken as answered, s."""


@pytest.fixture
def arm(request: pytest.FixtureRequest) -> IntegratingJoints:
    return IntegratingJoints(request.module.START_ANGLES)


@pytest.fixture
def emulator(request: pytest.FixtureRequest, arm: IntegratingJoints) -> Iterator[ServoChain]:
    with request.module.CHAIN(arm, request.module.IDS) as chain:
        yield chain
    assert chain.counters["handler_errors"] == 0


@pytest.fixture
def port(request: pytest.FixtureRequest, emulator: ServoChain) -> Iterator[PortHandler]:
    handler = PatientPort(emulator.port)
    assert handler.openPort()
    baud = getattr(request.module, "BAUD", None)
    if baud is not None:
        assert handler.setBaudRate(baud)
    yield handler
    handler.closePort()


@pytest.fixture
def packet(request: pytest.FixtureRequest) -> PacketHandler:
    return PacketHandler(request.module.PROTOCOL)


def simulate(emulator: ServoChain, arm: IntegratingJoints, steps: int) -> None:
    for _ in range(steps):
        emulator.update(DT)
        arm.step(DT)


@pytest.fixture
def raw(emulator: ServoChain) -> Iterator[serial.Serial]:
    """The chain's line as pyserial opens it, for the bytes the SDK never sends."""
    with serial.Serial(emulator.port, 1_000_000, timeout=QUIET_S) as connection:
        yield connection


def answered(raw: serial.Serial, request: bytes) -> bytes:
    """Write ``request``; every byte answered until the line is quiet for QUIET_S."""
    raw.write(request)
    answer = bytearray()
    while chunk := raw.read(max(raw.in_waiting, 1)):
        answer += chunk
    return bytes(answer)
