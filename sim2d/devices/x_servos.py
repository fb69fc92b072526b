"""A chain of emulated X-series servos (XM430-W350, the OpenManipulator-X's) on a pseudo-terminal:
a driver opens ``port`` (or the symlink) with the dynamixel-sdk's PacketHandler(2.0) or
pyserial as it would a U2D2, and each servo answers protocol 2.0 as the real one does.

Each servo keeps the X-series control table up to Present Temperature (146) with the
e-manual's defaults (model 1020, operating mode 3 = position, velocity limit 167, position
limits 0..4095, torque off, status return level 2...). PING answers the model number and
firmware; READ the table's bytes, Present Position read from the backend at that moment; WRITE
writes them all or none: a read-only byte, EEPROM (below 64) with torque on, or an address past
the table is the Access error, a Goal Position outside the position limits (position mode) or
a Goal Velocity over the velocity limit the Data Limit error. SYNC_WRITE and BULK_WRITE write
each listed servo; SYNC_READ and BULK_READ are answered by each listed servo in the list's
order; REBOOT clears a hardware error (torque off). Broadcast writes get no answer; a bad CRC
gets the CRC error, an unknown or malformed instruction the Instruction error. Status Return
Level is obeyed (0: PING only, 1: PING and reads). The answer leaves after the Return Delay
(2 us per unit). Faults are injected per servo as on the AX chain (``servo_chain``): ``fail``
(silent, or an overload: torque off, Hardware Error Status's overload bit and the alert bit in
every answer until a reboot), ``recover`` and ``corrupt``.

Motion, ``update(dt)`` every simulator step: in position mode each torque-enabled servo goes
towards its Goal Position at its Profile Velocity (0: the Velocity Limit), capped at the
Velocity Limit, landing on the goal; in velocity mode at its Goal Velocity. Present Velocity is
the backend's motion over the last step.
"""

from __future__ import annotations

import time

from protocols import dynamixel_v2 as dxl
from protocols import x_series_units as x_units
from protocols.dynamixel_v2 import (
    ALERT,
    SIZES,
    Address,
    HardwareError,
    Instruction,
    OperatingMode,
    StatusError,
)
from sim2d.devices.servo_chain import ChainServo, ServoChain, spoiled

MODEL_NUMBER = 1020
"""XM430-W350."""
FIRMWARE_VERSION = 45
TABLE_BYTES = 147
_DEFAULTS: dict[Address | int, tuple[int, int]] = {
    Address.MODEL_NUMBER: (MODEL_NUMBER, 2),
    Address.FIRMWARE_VERSION: (FIRMWARE_VERSION, 1),
    Address.BAUD_RATE: (1, 1),
    Address.RETURN_DELAY: (250, 1),
    Address.OPERATING_MODE: (OperatingMode.POSITION, 1),
    Address.MOVING_THRESHOLD: (10, 4),
    31: (80, 1),
    32: (160, 2),
    34: (95, 2),
    36: (885, 2),
    38: (1193, 2),
    Address.VELOCITY_LIMIT: (167, 4),
    Address.MAX_POSITION_LIMIT: (x_units.POSITION_MAX, 4),
    Address.SHUTDOWN: (52, 1),
    Address.STATUS_RETURN_LEVEL: (2, 1),
    84: (800, 2),
    144: (120, 2),
    Address.PRESENT_TEMPERATURE: (25, 1),
}
"""Entries of a fresh table other than 0 (e-manual, XM430-W350): moving threshold 10,
temperature limit 80 C, voltage limits 9.5..16 V, PWM limit 885, current limit 1193, velocity
limit 167 (4.0 rad/s), position limits 0..4095, shutdown on overheating, electrical shock and
overload, position P gain 800; present voltage 12.0 V and temperature 25 C."""
_READ_ONLY = frozenset((*range(0, 7), Address.HARDWARE_ERROR_STATUS, 69, *range(120, TABLE_BYTES)))
"""Model number and information, firmware version, Registered Instruction, Hardware Error
Status, and the present values from Realtime Tick (120) on."""


def default_table(servo_id: int) -> bytearray:
    table = bytearray(TABLE_BYTES)
    for address, (number, size) in _DEFAULTS.items():
        table[address : address + size] = dxl.value(number, size)
    table[Address.ID] = servo_id
    return table


class XServo(ChainServo):
    """One X-series servo: its control table and its answers to instruction packets. No I/O."""

    id_address = Address.ID
    delay_address = Address.RETURN_DELAY
    delay_us_per_unit = x_units.RETURN_DELAY_US_PER_UNIT

    def __init__(self, servo_id: int, return_delay_us: float, position_rad: float) -> None:
        super().__init__(default_table(servo_id), return_delay_us)
        self._set(Address.GOAL_POSITION, x_units.position_units(position_rad))
        self.sense_position(position_rad)

    def word(self, address: int) -> int:
        """The table's entry at ``address`` (its size, signed where it is)."""
        data = self.table[address : address + SIZES.get(address, 1)]
        return int.from_bytes(data, "little", signed=address in dxl.SIGNED)

    def _set(self, address: Address, number: int) -> None:
        size = SIZES.get(address, 1)
        self.table[address : address + size] = dxl.value(number, size)

    @property
    def hardware_error(self) -> int:
        return self.table[Address.HARDWARE_ERROR_STATUS]

    def _driven(self) -> bool:
        return bool(self.table[Address.TORQUE_ENABLE]) and not self.hardware_error

    def sense_position(self, position_rad: float) -> None:
        self._set(Address.PRESENT_POSITION, round(x_units.position_of_angle(position_rad)))

    def sense_speed(self, velocity_rad_s: float) -> None:
        """Present Velocity, and Moving: faster than the Moving Threshold."""
        units = x_units.velocity_units(velocity_rad_s)
        self._set(Address.PRESENT_VELOCITY, units)
        self.table[Address.MOVING] = abs(units) > self.word(Address.MOVING_THRESHOLD)

    def velocity_command(self, position_rad: float, dt: float) -> float:
        """Towards Goal Position at Profile Velocity (0: the limit), landing on it, or at Goal
        Velocity; 0 with torque off or a hardware error."""
        if not self._driven():
            return 0.0
        limit = x_units.rad_s_of_velocity_units(self.word(Address.VELOCITY_LIMIT))
        if self.table[Address.OPERATING_MODE] == OperatingMode.VELOCITY:
            velocity = x_units.rad_s_of_velocity_units(self.word(Address.GOAL_VELOCITY))
            return min(max(velocity, -limit), limit)
        profile = self.word(Address.PROFILE_VELOCITY)
        speed = min(x_units.rad_s_of_velocity_units(profile), limit) if profile else limit
        error = x_units.angle_of_units(self.word(Address.GOAL_POSITION)) - position_rad
        return min(max(error / dt, -speed), speed)

    def fail(self, silent: bool) -> None:
        """Silent: the servo no longer answers nor moves. Otherwise an overload: torque off,
        the overload bit in Hardware Error Status and the alert in every answer."""
        self.silent = silent
        if not silent:
            self.table[Address.HARDWARE_ERROR_STATUS] |= HardwareError.OVERLOAD
        self.table[Address.TORQUE_ENABLE] = 0

    def status_error(self, error: StatusError) -> int:
        """The error byte of an answer: ``error`` and the alert bit when in hardware error."""
        return int(error) | (ALERT if self.hardware_error else 0)

    def answers(self, instruction: int) -> bool:
        level = self.table[Address.STATUS_RETURN_LEVEL]
        reads = (Instruction.READ, Instruction.SYNC_READ, Instruction.BULK_READ)
        return (
            level >= 2 or instruction == Instruction.PING or (level == 1 and instruction in reads)
        )

    def carry_out(self, packet: dxl.Packet) -> tuple[StatusError, bytes]:
        """Carry out an instruction addressed to this servo alone: (error, parameters)."""
        if not packet.crc_ok:
            return StatusError.CRC, b""
        instruction, params = packet.instruction, packet.params
        if instruction == Instruction.PING:
            return StatusError.NONE, self.ping()
        if instruction == Instruction.READ and len(params) == 4:
            address, length = (int.from_bytes(params[i : i + 2], "little") for i in (0, 2))
            return self.read(address, length)
        if instruction == Instruction.WRITE and len(params) > 2:
            return self.write(int.from_bytes(params[:2], "little"), params[2:]), b""
        if instruction == Instruction.REBOOT:
            self.table[Address.HARDWARE_ERROR_STATUS] = 0
            self.table[Address.TORQUE_ENABLE] = 0
            return StatusError.NONE, b""
        return StatusError.INSTRUCTION, b""

    def ping(self) -> bytes:
        return bytes(self.table[0:2]) + bytes((self.table[Address.FIRMWARE_VERSION],))

    def read(self, address: int, length: int) -> tuple[StatusError, bytes]:
        if length < 1 or address + length > TABLE_BYTES:
            return StatusError.ACCESS, b""
        return StatusError.NONE, bytes(self.table[address : address + length])

    def write(self, address: int, data: bytes) -> StatusError:
        """Write all of ``data`` at ``address`` or none of it (see the module docstring)."""
        span = range(address, address + len(data))
        if not data or span.stop > TABLE_BYTES or any(a in _READ_ONLY for a in span):
            return StatusError.ACCESS
        if self.table[Address.TORQUE_ENABLE] and address < dxl.EEPROM_END:
            return StatusError.ACCESS
        table = bytearray(self.table)
        table[span.start : span.stop] = data
        if self._beyond_limits(table, span):
            return StatusError.DATA_LIMIT
        self.table[:] = table
        if self.hardware_error:
            self.table[Address.TORQUE_ENABLE] = 0
        return StatusError.NONE

    def _beyond_limits(self, table: bytearray, span: range) -> bool:
        def entry(address: Address) -> int:
            data = table[address : address + 4]
            return int.from_bytes(data, "little", signed=address in dxl.SIGNED)

        position_mode = table[Address.OPERATING_MODE] == OperatingMode.POSITION
        if Address.GOAL_POSITION in span and position_mode:
            goal = entry(Address.GOAL_POSITION)
            if not entry(Address.MIN_POSITION_LIMIT) <= goal <= entry(Address.MAX_POSITION_LIMIT):
                return True
        if Address.GOAL_VELOCITY in span:
            return abs(entry(Address.GOAL_VELOCITY)) > entry(Address.VELOCITY_LIMIT)
        return False


class XChainEmulator(ServoChain):
    """An X-series servo per joint of ``backend``, answering to ``ids`` in the joints' order
    (1..n when None)."""

    servo_type = XServo
    parser_type = dxl.PacketParser

    def _handle(self, packet: dxl.Packet) -> None:
        self.counters["packets"] += 1
        with self._lock:
            answers = self._answers(packet)
        if not answers and packet.id != dxl.BROADCAST_ID:
            self.counters["unanswered"] += 1
        for servo, error, params, delay, corruption in answers:
            time.sleep(delay)
            status = spoiled(dxl.status_packet, servo, error, params, corruption, 4)
            self.send(status, "status_sent")

    def _answers(self, packet: dxl.Packet) -> list[tuple[int, int, bytes, float, object]]:
        """Carry out ``packet`` (under the lock): the statuses to send, in order, as (id,
        error, parameters, delay before it, corruption)."""
        reads = self._broadcast(packet) if packet.id == dxl.BROADCAST_ID else None
        if reads is None:
            servo = self._servo(packet.id)
            if servo is None or servo.silent:
                return []
            if packet.instruction == Instruction.READ:
                self._sense(servo)
            error, params = servo.carry_out(packet)
            reads = [(servo, error, params)]
        return [
            (s.id, s.status_error(e), p, s.return_delay_s, s.corruption)
            for s, e, p in reads
            if not s.silent and s.answers(packet.instruction)
        ]

    def _broadcast(self, packet: dxl.Packet) -> list[tuple[XServo, StatusError, bytes]]:
        """Carry out a broadcast packet: the reads it asks for, in order (none for writes)."""
        params, instruction = packet.params, packet.instruction
        if not packet.crc_ok:
            return []
        if instruction == Instruction.PING:
            return [(s, StatusError.NONE, s.ping()) for s in self.servos]
        if instruction in (Instruction.WRITE, Instruction.REBOOT):
            for servo in self.servos:
                if not servo.silent:
                    servo.carry_out(packet)
            return []
        if instruction in (Instruction.SYNC_READ, Instruction.SYNC_WRITE) and len(params) > 4:
            address, length = (int.from_bytes(params[i : i + 2], "little") for i in (0, 2))
            if instruction == Instruction.SYNC_READ:
                self.counters["sync_reads"] += 1
                listed = [(i, address, length) for i in params[4:]]
                return self._reads(listed)
            self.counters["sync_writes"] += 1
            for servo_id, data in (dxl.blocks(params[4:], length) or {}).items():
                if (servo := self._servo(servo_id)) is not None and not servo.silent:
                    servo.write(address, data)
            return []
        bulk = dxl.bulk_blocks(params, instruction == Instruction.BULK_WRITE)
        if instruction == Instruction.BULK_READ and bulk:
            return self._reads([(i, a, n) for i, a, n, _ in bulk])
        if instruction == Instruction.BULK_WRITE and bulk:
            for servo_id, address, _, data in bulk:
                if (servo := self._servo(servo_id)) is not None and not servo.silent:
                    servo.write(address, data)
        return []

    def _reads(self, listed: list[tuple[int, int, int]]) -> list:
        out = []
        for servo_id, address, length in listed:
            servo = self._servo(servo_id)
            if servo is not None and not servo.silent:
                self._sense(servo)
                out.append((servo, *servo.read(address, length)))
        return out
