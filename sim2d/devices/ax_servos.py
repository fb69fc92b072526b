"""A chain of emulated AX-18A servos on a pseudo-terminal: a driver opens ``port`` (or the
symlink) with the dynamixel-sdk or pyserial as it would a U2D2 on the servos' bus, and each
servo answers protocol 1.0 as the real one does.

Each servo keeps the AX-18A's 50-byte control table (defaults of the e-manual: model 18, baud
1 = 1 Mbps, angle limits 0 and 1023, torque off...). PING answers an empty status; READ answers
the table's bytes, Present Position read from the backend at that moment; WRITE and REG_WRITE +
ACTION write it, read-only bytes left alone; a Goal Position outside the CW/CCW angle limits is
clamped to them and answered with the ANGLE_LIMIT bit; SYNC_WRITE writes each listed servo;
RESET restores the defaults (id 1). Broadcast packets get no answer; a bad checksum gets the
CHECKSUM bit, an unknown or malformed instruction the INSTRUCTION bit, a read or write past
the table the RANGE bit. Status Return Level is obeyed (0: PING only, 1: PING and READ). The
answer leaves after the servo's Return Delay (2 us per unit), slept as the real servo waits.
Faults are injected per servo: ``fail`` (silent, or an overload shutdown), ``recover`` (a
silent servo answers again) and ``corrupt`` (its status packets truncated, with a bad checksum,
another id or a parameter short).

Motion: ``update(dt)``, called every simulator step, drives each torque-enabled servo towards
its Goal Position at its Moving Speed (0: full speed) capped at the AX-18A's 97 rpm, ending
exactly on the goal, and hands the velocities to the backend. Present Speed is the backend's
motion over the last step; Present Load reads 0 (the backend reports no torque). Wheel mode
(both angle limits 0) is not emulated.

The backend is the world the arm moves in (``sim2d`` or a test double); the emulator calls it
from its reader thread and from ``update`` under one lock, so it need not be thread-safe
against the emulator, only against whoever else steps it.
"""

from __future__ import annotations

import math
import time

from protocols import dynamixel_v1 as dxl
from protocols.dynamixel_v1 import Address, Instruction, StatusError
from sim2d.devices.servo_chain import ChainServo, ServoChain, spoiled

MODEL_NUMBER = 18
MAX_SPEED_RAD_S = 97.0 * 2.0 * math.pi / 60.0
"""The AX-18A's no-load speed at 12 V, 97 rpm: Moving Speed 0 and anything above it."""
TABLE_BYTES = 50
_DEFAULTS: dict[int, int] = {
    0: MODEL_NUMBER,
    Address.BAUD_RATE: 1,
    Address.RETURN_DELAY: 250,
    Address.CCW_ANGLE_LIMIT: 0xFF,
    Address.CCW_ANGLE_LIMIT + 1: 0x03,
    11: 75,
    12: 60,
    13: 140,
    14: 0xFF,
    15: 0x03,
    Address.STATUS_RETURN_LEVEL: 2,
    17: 36,
    18: 36,
    Address.CW_COMPLIANCE_MARGIN: 1,
    27: 1,
    28: 32,
    29: 32,
    34: 0xFF,
    35: 0x03,
    42: 120,
    43: 25,
    48: 32,
}
"""Non-zero bytes of a fresh table (e-manual): temperature limit 75 C, voltage limits 6..14 V,
max torque and torque limit 1023, alarm LED and shutdown 36, compliance margins 1 and slopes 32,
punch 32; present voltage 12.0 V and temperature 25 C stand for a cool servo on 12 V."""
_READ_ONLY = frozenset((0, 1, 2, *range(36, 47)))
"""Model number, firmware version and the present values 36..46 (position, speed, load,
voltage, temperature, Registered, Moving): a write leaves them as they are."""


def default_table(servo_id: int) -> bytearray:
    table = bytearray(TABLE_BYTES)
    for address, value in _DEFAULTS.items():
        table[address] = value
    table[Address.ID] = servo_id
    return table


class AXServo(ChainServo):
    """One AX-18A: its control table and its answers to instruction packets. No I/O."""

    id_address = Address.ID
    delay_address = Address.RETURN_DELAY
    delay_us_per_unit = dxl.RETURN_DELAY_US_PER_UNIT

    def __init__(self, servo_id: int, return_delay_us: float, position_rad: float) -> None:
        super().__init__(default_table(servo_id), return_delay_us)
        self.overloaded = False
        self._registered: tuple[int, bytes] | None = None
        self._set_word(Address.GOAL_POSITION, dxl.position_units(position_rad))
        self.sense_position(position_rad)
        self.sense_speed(0.0)

    def word(self, address: int) -> int:
        """The control table's word at ``address`` (low byte first)."""
        return int.from_bytes(self.table[address : address + 2], "little")

    def _set_word(self, address: int, value: int) -> None:
        self.table[address : address + 2] = dxl.word(value)

    def sense_position(self, position_rad: float) -> None:
        """Present Position, and Moving: driven and farther from the goal than the compliance
        margin."""
        position = dxl.position_units(position_rad)
        self._set_word(Address.PRESENT_POSITION, position)
        away = (
            abs(self.word(Address.GOAL_POSITION) - position)
            > self.table[Address.CW_COMPLIANCE_MARGIN]
        )
        self.table[Address.MOVING] = away and self._driven()

    def _driven(self) -> bool:
        return bool(self.table[Address.TORQUE_ENABLE]) and not self.overloaded

    def sense_speed(self, velocity_rad_s: float) -> None:
        self._set_word(Address.PRESENT_SPEED, dxl.signed_speed_units(velocity_rad_s))

    def velocity_command(self, position_rad: float, dt: float) -> float:
        """Towards Goal Position at Moving Speed (0: full speed), landing on the goal; 0 with
        torque off or after an overload shutdown."""
        if not self._driven():
            return 0.0
        speed_units = self.word(Address.MOVING_SPEED) & dxl.SPEED_MAX
        speed = dxl.rad_s_of_speed_units(speed_units) if speed_units else MAX_SPEED_RAD_S
        speed = min(speed, MAX_SPEED_RAD_S)
        error = dxl.angle_of_units(self.word(Address.GOAL_POSITION)) - position_rad
        return min(max(error / dt, -speed), speed)

    def fail(self, silent: bool) -> None:
        """Silent: the servo no longer answers nor moves. Otherwise it shuts down as on an
        overload: torque off for good, the OVERLOAD bit in every answer."""
        self.silent = silent
        self.overloaded = self.overloaded or not silent
        self.table[Address.TORQUE_ENABLE] = 0

    def execute(self, packet: dxl.Packet) -> tuple[int, bytes] | None:
        """Carry out a packet addressed to this servo or broadcast; the (error, params) of the
        status to answer, or None when the servo does not answer."""
        if self.silent:
            return None
        error, params = self._carry_out(packet)
        if self.overloaded:
            error |= StatusError.OVERLOAD
        if packet.id == dxl.BROADCAST_ID or not self._answers(packet.instruction):
            return None
        return int(error), params

    def _answers(self, instruction: int) -> bool:
        level = self.table[Address.STATUS_RETURN_LEVEL]
        return (
            level >= 2
            or instruction == Instruction.PING
            or (level == 1 and instruction == Instruction.READ)
        )

    def _carry_out(self, packet: dxl.Packet) -> tuple[StatusError, bytes]:
        if not packet.checksum_ok:
            return StatusError.CHECKSUM, b""
        instruction, params = packet.instruction, packet.params
        if instruction == Instruction.PING:
            return StatusError(0), b""
        if instruction == Instruction.READ and len(params) == 2:
            return self._read(params[0], params[1])
        if instruction == Instruction.WRITE and len(params) >= 2:
            return self._write(params[0], params[1:]), b""
        if instruction == Instruction.REG_WRITE and len(params) >= 2:
            return self._register(params[0], params[1:]), b""
        if instruction == Instruction.ACTION:
            return self._action(), b""
        if instruction == Instruction.SYNC_WRITE and len(params) >= 2:
            return self._sync_write(params[0], params[1], params[2:]), b""
        if instruction == Instruction.RESET:
            self.table[:] = default_table(1)
            return StatusError(0), b""
        return StatusError.INSTRUCTION, b""

    def _read(self, address: int, length: int) -> tuple[StatusError, bytes]:
        if address + length > TABLE_BYTES:
            return StatusError.RANGE, b""
        return StatusError(0), bytes(self.table[address : address + length])

    def _write(self, address: int, data: bytes) -> StatusError:
        if address + len(data) > TABLE_BYTES:
            return StatusError.RANGE
        for offset, value in enumerate(data):
            if address + offset not in _READ_ONLY:
                self.table[address + offset] = value
        if self.overloaded:
            self.table[Address.TORQUE_ENABLE] = 0
        if address <= Address.GOAL_POSITION + 1 and address + len(data) > Address.GOAL_POSITION:
            return self._clamp_goal()
        return StatusError(0)

    def _clamp_goal(self) -> StatusError:
        goal = self.word(Address.GOAL_POSITION)
        low, high = self.word(Address.CW_ANGLE_LIMIT), self.word(Address.CCW_ANGLE_LIMIT)
        clamped = min(max(goal, low), high)
        self._set_word(Address.GOAL_POSITION, clamped)
        return StatusError.ANGLE_LIMIT if clamped != goal else StatusError(0)

    def _register(self, address: int, data: bytes) -> StatusError:
        if address + len(data) > TABLE_BYTES:
            return StatusError.RANGE
        self._registered = (address, data)
        self.table[Address.REGISTERED] = 1
        return StatusError(0)

    def _action(self) -> StatusError:
        """Carry out the registered write; INSTRUCTION when there is none."""
        if self._registered is None:
            return StatusError.INSTRUCTION
        address, data = self._registered
        self._registered = None
        self.table[Address.REGISTERED] = 0
        return self._write(address, data)

    def _sync_write(self, address: int, length: int, blocks: bytes) -> StatusError:
        """Write this servo's block of a Sync Write (``id, data`` repeated), if it has one."""
        step = length + 1
        if len(blocks) % step:
            return StatusError.INSTRUCTION
        for start in range(0, len(blocks), step):
            if blocks[start] == self.id:
                return self._write(address, blocks[start + 1 : start + step])
        return StatusError(0)


class AXChainEmulator(ServoChain):
    """A servo per joint of ``backend``, answering to ``ids`` in the joints' order (1..n when
    None)."""

    servo_type = AXServo
    parser_type = dxl.PacketParser

    def _handle(self, packet: dxl.Packet) -> None:
        self.counters["packets"] += 1
        with self._lock:
            if packet.id == dxl.BROADCAST_ID:
                for servo in self.servos:
                    servo.execute(packet)
                if packet.instruction == Instruction.SYNC_WRITE:
                    self.counters["sync_writes"] += 1
                return
            servo = self._servo(packet.id)
            if servo is None:
                self.counters["unanswered"] += 1
                return
            if packet.instruction == Instruction.READ:
                self._sense(servo)
            answer_id = servo.id
            answer = servo.execute(packet)
            delay = servo.return_delay_s
            corruption = servo.corruption
        if answer is None:
            self.counters["unanswered"] += 1
            return
        time.sleep(delay)
        self.send(spoiled(dxl.status_packet, answer_id, *answer, corruption, 2), "status_sent")
