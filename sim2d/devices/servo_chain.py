"""What every emulated chain of Dynamixel servos shares, whatever its protocol: the world the
servos move (``ServoBackend``), the chain on a pseudo-terminal with its fault injection
(``ServoChain``), what each of its servos keeps (``ChainServo``), and status packets spoiled
on their way out (``spoiled``).

A servo of a chain (``AXServo``, ``XServo``) has an ``id``, ``silent``, ``corruption``,
``fail(silent)``, ``word(address)``, ``sense_position(rad)``, ``sense_speed(rad_s)`` and
``velocity_command(position_rad, dt)``; the chain's ``_handle`` answers a packet.
"""

from __future__ import annotations

import threading
import time
from collections import Counter
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Protocol

from protocols.dynamixel_v1 import StatusFault
from sim2d.devices.pty_link import SerialDevice

ANSWER_TIMEOUT_S = 1.0
"""How long a driver of an emulated chain awaits a servo's answer, s (deploy/emulated.yaml's
``answer_timeout_s``): the emulator's thread, starved on a busy machine, may answer tens or
hundreds of milliseconds late, and a late answer must not pass for a silent servo."""


class ServoBackend(Protocol):
    def joint_positions(self) -> Sequence[float]:
        """Joint angles (rad), one per servo in id order."""

    def set_joint_velocities(self, velocities: Sequence[float]) -> None:
        """Joint velocity commands (rad/s), one per servo in id order."""


class IntegratingJoints:
    """The plainest world for the servos: joints that move at the velocities they command,
    ``step(dt)`` at a time (tests and benchmarks without the simulator)."""

    def __init__(self, angles: Sequence[float]) -> None:
        self.angles = list(angles)
        self.velocities = [0.0] * len(self.angles)

    def joint_positions(self) -> Sequence[float]:
        return tuple(self.angles)

    def set_joint_velocities(self, velocities: Sequence[float]) -> None:
        self.velocities = list(velocities)

    def step(self, dt: float) -> None:
        self.angles = [q + v * dt for q, v in zip(self.angles, self.velocities, strict=True)]


class ChainServo:
    """What every emulated servo keeps: its control table, its Return Delay Time (at
    ``delay_address``, ``delay_us_per_unit`` a unit), its id (at ``id_address``), whether it
    is silent, and how its status packets are spoiled."""

    id_address: int
    delay_address: int
    delay_us_per_unit: float

    def __init__(self, table: bytearray, return_delay_us: float) -> None:
        self.table = table
        self.table[self.delay_address] = min(
            max(round(return_delay_us / self.delay_us_per_unit), 0), 254
        )
        self.silent = False
        self.corruption: StatusFault | None = None
        """How this servo's status packets are spoiled on their way out (fault injection)."""

    @property
    def id(self) -> int:
        return self.table[self.id_address]

    @property
    def return_delay_s(self) -> float:
        return self.table[self.delay_address] * self.delay_us_per_unit * 1e-6


COUNTERS = (
    "packets",
    "bad_checksums",
    "skipped_bytes",
    "unanswered",
    "status_sent",
    "sync_writes",
    "sync_reads",
    "handler_errors",
)


class ServoChain(SerialDevice):
    """Servos on one pseudo-terminal, a ``servo_type(id, return_delay_us, position)`` per
    joint of ``backend``, answering to ``ids`` in the joints' order (1..n when None); a
    ``parser_type()`` frames the driver's packets (``feed``, ``bad_checksums``,
    ``skipped_bytes``). ``instructions`` counts the packets received by instruction. With
    ``baud`` (bit/s) the servos listen at that rate only: bytes written while the port is set
    to another are garbled for them and dropped (``wrong_baud_bytes``), as on a real bus."""

    servo_type: Callable[[int, float, float], Any]
    parser_type: Callable[[], Any]

    def __init__(
        self,
        backend: ServoBackend,
        ids: Sequence[int] | None = None,
        link: Path | None = None,
        return_delay_us: float = 500.0,
        baud: int | None = None,
    ) -> None:
        positions = backend.joint_positions()
        ids = range(1, len(positions) + 1) if ids is None else ids
        self._backend = backend
        self.servos = [
            self.servo_type(servo_id, return_delay_us, position)
            for servo_id, position in zip(ids, positions, strict=True)
        ]
        self._previous_positions: list[float] = list(backend.joint_positions())
        super().__init__(link, (*COUNTERS, "wrong_baud_bytes"))
        self._parser = self.parser_type()
        self._baud = baud
        self.instructions: Counter[int] = Counter()

    def fail(self, servo_id: int, silent: bool = True) -> None:
        """Fault injection (see the servo's ``fail``)."""
        with self._lock:
            self._named(servo_id).fail(silent)

    def stall(self, seconds: float) -> None:
        """Fault injection: no packet carried out for ``seconds`` from now, as when a busy
        machine starves the chain's thread (its answers come late); returns at once."""
        begun = threading.Event()

        def hold() -> None:
            with self._lock:
                begun.set()
                time.sleep(seconds)

        threading.Thread(target=hold, name="servo-stall", daemon=True).start()
        begun.wait()

    def recover(self, servo_id: int) -> None:
        """A silent servo answers again, its torque off as after a brown-out."""
        with self._lock:
            self._named(servo_id).silent = False

    def corrupt(self, servo_id: int, fault: StatusFault | None) -> None:
        """Spoil every status packet of ``servo_id`` as ``fault`` says (TRUNCATED: cut after
        its id; CHECKSUM: the checksum's last byte inverted; WRONG_ID: the next id's;
        WRONG_LENGTH: one parameter short); None sends them whole again."""
        if fault is StatusFault.SILENT:
            raise ValueError("a silent servo is fail(id), not a corrupt answer")
        with self._lock:
            self._named(servo_id).corruption = fault

    def words(self, address: int) -> list[int]:
        """Every servo's value at ``address``, read at one moment (no Sync Write half done)."""
        with self._lock:
            return [servo.word(address) for servo in self.servos]

    def _named(self, servo_id: int) -> Any:
        servo = self._servo(servo_id)
        if servo is None:
            raise KeyError(f"no servo {servo_id} on the chain, ids {self._ids()}")
        return servo

    def update(self, dt: float) -> None:
        """One simulator step of dt seconds: measure each joint's motion since the last step,
        then command every joint's velocity towards its goal."""
        if dt <= 0.0:
            raise ValueError(f"update needs a positive step, got dt = {dt} s")
        with self._lock:
            positions = list(self._backend.joint_positions())
            velocities = []
            for servo, position, previous in zip(
                self.servos, positions, self._previous_positions, strict=True
            ):
                servo.sense_position(position)
                servo.sense_speed((position - previous) / dt)
                velocities.append(servo.velocity_command(position, dt))
            self._previous_positions = positions
            self._backend.set_joint_velocities(velocities)

    def _sense(self, servo: Any) -> None:
        """The servo's Present Position read from the backend now (a read asks for it)."""
        servo.sense_position(self._backend.joint_positions()[self.servos.index(servo)])

    def _ids(self) -> list[int]:
        return [servo.id for servo in self.servos]

    def _servo(self, servo_id: int) -> Any:
        return next((servo for servo in self.servos if servo.id == servo_id), None)

    def receive(self, data: bytes) -> None:
        if self._baud is not None and self._pty.baud() != self._baud:
            self.counters["wrong_baud_bytes"] += len(data)
            return
        packets = self._parser.feed(data)
        # Counted before any answer goes out: whoever has an answer sees its packet counted.
        self.counters["bad_checksums"] = self._parser.bad_checksums
        self.counters["skipped_bytes"] = self._parser.skipped_bytes
        for packet in packets:
            self.instructions[packet.instruction] += 1
            self._handle_guarded(packet)

    def _handle_guarded(self, packet: Any) -> None:
        """A fault in handling one packet is counted, not fatal: a bus keeps going."""
        try:
            self._handle(packet)
        except Exception:
            self.counters["handler_errors"] += 1

    def _handle(self, packet: Any) -> None:
        raise NotImplementedError


def spoiled(
    status: Callable[[int, int, bytes], bytes],
    servo_id: int,
    error: int,
    params: bytes,
    fault: StatusFault | None,
    id_at: int,
) -> bytes:
    """The status packet ``status(servo_id, error, params)`` as ``fault`` spoils it (see
    ``ServoChain.corrupt``); ``id_at`` is the id's offset in the packet."""
    if fault is StatusFault.WRONG_ID:
        return status((servo_id + 1) % 0xFE, error, params)
    if fault is StatusFault.WRONG_LENGTH:
        return status(servo_id, error, params[:-1])
    packet = status(servo_id, error, params)
    if fault is StatusFault.TRUNCATED:
        return packet[: id_at + 3]
    if fault is StatusFault.CHECKSUM:
        return packet[:-1] + bytes([packet[-1] ^ 0xFF])
    return packet
