"""The fixtures of the emulated servo chains' tests, whatever their protocol. A test module
declares ``CHAIN`` (the emulator's class), ``IDS``, ``START_ANGLES``, ``PROTOCOL`` (the SDK's
1.0 or 2.0), ``PROBE`` (an id of ``IDS`` its raw exchanges never address: ``exchange``) and,
when its port is set to a baud rate, ``BAUD``."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import ModuleType

import pytest
import serial
from dynamixel_sdk import PacketHandler, PortHandler

from components.servo_bus import BusPort
from protocols import dynamixel_v1, dynamixel_v2
from sim2d.devices.servo_chain import ANSWER_TIMEOUT_S, IntegratingJoints, ServoChain

DT = 0.01
"""The world's and the servos' step, s."""
SAFETY_S = 30.0
"""How long an exchange, or the SDK, waits for an answer at most: a safety net only, each wait
ends as soon as the answer is there. (The emulator's threads share this process's interpreter
with the SDK's polling: on a loaded machine an answer came later than a driver's 1 s.)"""
PROTOCOLS: dict[float, ModuleType] = {1.0: dynamixel_v1, 2.0: dynamixel_v2}
Exchange = Callable[[bytes], list]
"""The ``exchange`` fixture: an instruction's bytes in, the packets answered to them out."""


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
    handler = BusPort(emulator.port, SAFETY_S)
    assert handler.openPort()
    baud = getattr(request.module, "BAUD", None)
    if baud is not None:
        assert handler.setBaudRate(baud)
    yield handler
    handler.closePort()


@pytest.fixture
def packet(request: pytest.FixtureRequest) -> PacketHandler:
    return PacketHandler(request.module.PROTOCOL)


@contextmanager
def silent_awaited(port: BusPort) -> Iterator[None]:
    """Within: the port awaits an answer as an emulated chain's driver does (``ANSWER_TIMEOUT_S``),
    for a servo that never answers (a test's wait is otherwise ``SAFETY_S``)."""
    port.answer_timeout_ms = ANSWER_TIMEOUT_S * 1e3
    try:
        yield
    finally:
        port.answer_timeout_ms = SAFETY_S * 1e3


def simulate(emulator: ServoChain, arm: IntegratingJoints, steps: int) -> None:
    for _ in range(steps):
        emulator.update(DT)
        arm.step(DT)


@pytest.fixture
def raw(emulator: ServoChain) -> Iterator[serial.Serial]:
    """The chain's line as pyserial opens it, for the bytes the SDK never sends."""
    with serial.Serial(emulator.port, 1_000_000, timeout=DT) as connection:
        yield connection


@pytest.fixture
def exchange(request: pytest.FixtureRequest, raw: serial.Serial) -> Exchange:
    """``exchange(request)``: write ``request`` and a ping of the module's ``PROBE`` behind it;
    every packet answered to ``request``. The servos answer in the order they are asked, so
    every answer to ``request``, however late a busy machine makes it, comes before the
    probe's, and none after: no wait on a quiet line, which a starved emulator breaks."""
    protocol = PROTOCOLS[request.module.PROTOCOL]
    probe = request.module.PROBE

    def exchanged(instruction: bytes) -> list:
        raw.write(instruction + protocol.instruction_packet(probe, protocol.Instruction.PING))
        parser, answers = protocol.PacketParser(), []
        deadline = time.monotonic() + SAFETY_S
        while not any(packet.id == probe for packet in answers):
            assert time.monotonic() < deadline, f"no answer to the probe in {SAFETY_S} s"
            answers += parser.feed(raw.read(max(raw.in_waiting, 1)))
        assert answers[-1].id == probe and answers[-1].error == 0, answers
        return answers[:-1]

    return exchanged
