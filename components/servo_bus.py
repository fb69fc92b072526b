"""The arm driver's servo bus, one class per Dynamixel protocol: what the driver
(``components.arm_driver``) says to its servos and how it reads their answers, in joint-neutral
terms (positions in units, speeds in rad/s), through ROBOTIS's dynamixel-sdk.

``AXBus``: AX-18A servos on protocol 1.0 (Goal Position and Moving Speed, 0 meaning full
speed). ``XBus``: X-series servos (XM430, XL430) on protocol 2.0, in position mode (Profile
Velocity and Goal Position, 0 meaning no limit); torque is enabled only after the operating
mode is position and the goal is where the servo is, and an answer with the alert bit is
followed by a read of Hardware Error Status, its bits counted by name.

Each answer is checked by the protocol's ``status_fault``, so that a fault is named for its
servo. ``AXBus`` reads one servo at a time; ``XBus`` reads them all in one Sync Read, and one at
a time only when an answer of the Sync Read did not come whole, in time and from its servo (one
instruction packet a cycle instead of one per servo: one USB round trip instead of one per
servo on a U2D2). Both write every goal in one Sync Write.

Every answer, whichever of the SDK's calls asks for it, is awaited on the bus's ``BusPort``: at
least the bus's answer timeout, the SDK's own per-packet timeout when that is longer.
"""

from __future__ import annotations

from collections.abc import Sequence

from dynamixel_sdk import COMM_SUCCESS, GroupSyncWrite, PacketHandler, PortHandler

from protocols import dynamixel_v1 as dxl1
from protocols import dynamixel_v2 as dxl2
from protocols import x_series_units as x_units
from protocols.dynamixel_v1 import StatusFault

HOLD_SPEED = 1
"""The speed of a held joint, units: the slowest there is (0 would mean full speed)."""
Reading = tuple[tuple[int, float] | None, StatusFault | None, int]
"""A servo's Present Position (units) and speed (rad/s), or what is wrong with its answer (then
None); and the answer's error byte."""
READ_WAIT_S = 0.001
"""How long one read of the serial port waits for bytes before the SDK looks again (s)."""


class BusPort(PortHandler):
    """The SDK's port, awaiting every answer at least ``answer_timeout_s``: the SDK sets its own
    timeout per packet (34 ms for a short one at 1 Mbit/s: twice the USB latency timer and
    the packet's bytes), which stays when it is the longer. A real servo answers within a
    millisecond or two, and 0 keeps the SDK's, so that a silent servo holds the arm within
    two cycles at 50 Hz; an emulated servo on a busy machine may answer much later, and is
    given a generous timeout (deploy/emulated*.yaml) not to be taken for a silent one."""

    def __init__(self, name: str, answer_timeout_s: float = 0.0) -> None:
        super().__init__(name)
        self.answer_timeout_ms = answer_timeout_s * 1e3

    def setPacketTimeout(self, packet_length: int) -> None:  # noqa: N802 (the SDK's name)
        super().setPacketTimeout(packet_length)
        self.packet_timeout = max(self.packet_timeout, self.answer_timeout_ms)

    def setPacketTimeoutMillis(self, msec: float) -> None:  # noqa: N802 (the SDK's name)
        super().setPacketTimeoutMillis(max(msec, self.answer_timeout_ms))


def open_port(port: PortHandler, baud: int) -> bool:
    """Open ``port`` at ``baud``; False when it cannot be. The SDK opens it non-blocking and
    spins on empty reads while a servo answers (a third of a core at 50 Hz x 5 servos, and a
    thread in the same process starved of the GIL); a read that waits up to READ_WAIT_S for
    bytes gives the core back and notices a silent servo at most that much later."""
    try:
        opened = port.openPort() and port.setBaudRate(baud)
    except OSError:  # pyserial's SerialException is one
        return False
    if opened:
        port.ser.timeout = READ_WAIT_S
    return opened


class ServoBus:
    """What both protocols share: the port (``port_name``, each answer awaited at least
    ``answer_timeout_s``: ``BusPort``) and the SDK's packet handler."""

    protocol = 1.0
    position_max: int
    units_per_rad: float
    speed_max: int
    error_names: tuple[str, ...]
    """Every name an answer's error can be counted under."""
    read_bytes: int

    def __init__(self, port_name: str, answer_timeout_s: float = 0.0) -> None:
        self.port = BusPort(port_name, answer_timeout_s)
        self.packet = PacketHandler(self.protocol)

    def result_text(self, result: int) -> str:
        return self.packet.getTxRxResult(result)

    def read_all(self, ids: Sequence[int]) -> list[Reading] | None:
        """Every servo's reading (as ``read`` gives it) at once; None when they are to be read
        one at a time."""
        return None


class AXBus(ServoBus):
    """AX-18A servos, protocol 1.0."""

    protocol = 1.0
    position_max = dxl1.POSITION_MAX
    units_per_rad = dxl1.POSITION_UNITS_PER_RAD
    speed_max = dxl1.SPEED_MAX
    error_names = tuple(bit.name.lower() for bit in dxl1.StatusError)
    read_bytes = 4
    """Present Position and Present Speed, from address 36."""

    position_of_angle = staticmethod(dxl1.position_of_angle)
    position_units = staticmethod(dxl1.position_units)
    angle_of_units = staticmethod(dxl1.angle_of_units)
    speed_units = staticmethod(dxl1.moving_speed)

    def errors(self, servo: int, error: int) -> list[str]:
        """The names of the bits set in a status packet's error byte."""
        return [bit.name.lower() for bit in dxl1.StatusError if error & bit]

    def read(self, servo: int) -> Reading:
        """One servo's reading."""
        result = self.packet.readTx(
            self.port, servo, dxl1.Address.PRESENT_POSITION, self.read_bytes
        )
        answer = b""
        if result == COMM_SUCCESS:
            rx, _ = self.packet.rxPacket(self.port)
            answer = bytes(rx)
        fault = dxl1.status_fault(answer, servo, self.read_bytes)
        if fault is not None:
            return None, fault, 0
        data = answer[5 : 5 + self.read_bytes]
        speed = dxl1.rad_s_of_speed_units(data[2] | data[3] << 8)
        return (data[0] | data[1] << 8, speed), None, answer[4]

    def enable_torque(self, servo: int) -> int | None:
        """Torque on; the answer's error byte, None without an answer."""
        result, error = self.packet.write1ByteTxRx(self.port, servo, dxl1.Address.TORQUE_ENABLE, 1)
        return error if result == COMM_SUCCESS else None

    def write_goals(self, ids: Sequence[int], goals: Sequence[int], speeds: Sequence[int]) -> int:
        """Every servo's Goal Position and Moving Speed in one Sync Write; the SDK's result."""
        group = GroupSyncWrite(self.port, self.packet, dxl1.Address.GOAL_POSITION, 4)
        for servo, goal, speed in zip(ids, goals, speeds, strict=True):
            group.addParam(servo, [*dxl1.word(goal), *dxl1.word(speed)])
        return group.txPacket()


class XBus(ServoBus):
    """X-series servos, protocol 2.0, in position mode."""

    protocol = 2.0
    position_max = x_units.POSITION_MAX
    units_per_rad = x_units.POSITION_UNITS_PER_RAD
    speed_max = x_units.PROFILE_VELOCITY_MAX
    error_names = (
        *(e.name.lower() for e in dxl2.StatusError if e),
        *(bit.name.lower() for bit in dxl2.HardwareError),
    )
    read_bytes = 8
    """Present Velocity and Present Position, from address 128."""

    position_of_angle = staticmethod(x_units.position_of_angle)
    position_units = staticmethod(x_units.position_units)
    angle_of_units = staticmethod(x_units.angle_of_units)
    speed_units = staticmethod(x_units.profile_velocity)

    def errors(self, servo: int, error: int) -> list[str]:
        """The name of a status packet's error number, and with the alert bit those of the
        bits of the servo's Hardware Error Status (read now)."""
        names = []
        if error & ~dxl2.ALERT:
            number = error & ~dxl2.ALERT
            known = number <= max(dxl2.StatusError)
            names.append(dxl2.StatusError(number).name.lower() if known else "result_fail")
        if error & dxl2.ALERT:
            status, result, _ = self.packet.read1ByteTxRx(
                self.port, servo, dxl2.Address.HARDWARE_ERROR_STATUS
            )
            if result == COMM_SUCCESS:
                names += [bit.name.lower() for bit in dxl2.HardwareError if status & bit]
        return names

    def _receive(self) -> bytes:
        """The bytes of one status packet from its header on, as far as they came before the
        packet timeout; empty when no header came."""
        buffer = bytearray()
        header = len(dxl2.HEADER)
        while True:
            end = dxl2.packet_end(buffer) if buffer[:header] == dxl2.HEADER else None
            wanted = (end or dxl2.MIN_STATUS_BYTES) - len(buffer)
            if wanted <= 0:
                return bytes(buffer[:end])
            buffer += self.port.readPort(wanted)
            start = buffer.find(dxl2.HEADER)
            if start != 0:
                del buffer[: start if start > 0 else max(len(buffer) - header + 1, 0)]
            if self.port.isPacketTimeout():
                return bytes(buffer)

    def _answer(self, servo: int) -> bytes:
        """``servo``'s answer. A whole status packet of another servo (a late answer to an
        earlier read) is passed over, as the SDK's txRxPacket does; it is the answer only when
        nothing follows it before the timeout (``WRONG_ID``)."""
        answer = self._receive()
        while dxl2.status_fault(answer, servo, self.read_bytes) is StatusFault.WRONG_ID:
            following = self._receive()
            if not following:
                return answer
            answer = following
        return answer

    def read(self, servo: int) -> Reading:
        """One servo's reading (Present Position and Present Velocity)."""
        result = self.packet.readTx(
            self.port, servo, dxl2.Address.PRESENT_VELOCITY, self.read_bytes
        )
        answer = b""
        if result == COMM_SUCCESS:
            answer = self._answer(servo)
            self.port.is_using = False
        return self._reading(answer, servo)

    def _reading(self, answer: bytes, servo: int) -> Reading:
        fault = dxl2.status_fault(answer, servo, self.read_bytes)
        if fault is not None:
            return None, fault, 0
        error, data = dxl2.status_data(answer)
        velocity = x_units.rad_s_of_velocity_units(dxl2.signed(data[:4]))
        return (dxl2.signed(data[4:8]), velocity), None, error

    def read_all(self, ids: Sequence[int]) -> list[Reading] | None:
        """Every servo's reading from one Sync Read; None unless every answer came whole, in
        time and from its servo (then each servo is read on its own, which names the fault)."""
        self.port.clearPort()
        packet = dxl2.sync_read(dxl2.Address.PRESENT_VELOCITY, self.read_bytes, ids)
        if self.port.writePort(packet) != len(packet):
            return None
        self.port.setPacketTimeout((dxl2.MIN_STATUS_BYTES + self.read_bytes) * len(ids))
        answers = {}
        for _ in ids:
            answer = self._receive()
            if len(answer) < dxl2.MIN_STATUS_BYTES:
                return None
            answers[answer[4]] = answer
        readings = [self._reading(answers.get(servo, b""), servo) for servo in ids]
        return None if any(fault for _, fault, _ in readings) else readings

    def enable_torque(self, servo: int) -> int | None:
        """Torque on in position mode, the goal where the servo is: with torque off, the
        operating mode set to position if it is not, and the goal to the present position,
        first. The last answer's error byte; None when one did not come."""
        torque, result, error = self.packet.read1ByteTxRx(
            self.port, servo, dxl2.Address.TORQUE_ENABLE
        )
        if result != COMM_SUCCESS:
            return None
        if not torque:
            mode, result, error = self.packet.read1ByteTxRx(
                self.port, servo, dxl2.Address.OPERATING_MODE
            )
            if result == COMM_SUCCESS and mode != dxl2.OperatingMode.POSITION:
                result, error = self.packet.write1ByteTxRx(
                    self.port, servo, dxl2.Address.OPERATING_MODE, dxl2.OperatingMode.POSITION
                )
            position, result, error = self.packet.read4ByteTxRx(
                self.port, servo, dxl2.Address.PRESENT_POSITION
            )
            if result != COMM_SUCCESS:
                return None
            goal = min(max(dxl2.signed(dxl2.value(position, 4)), 0), x_units.POSITION_MAX)
            result, error = self.packet.write4ByteTxRx(
                self.port, servo, dxl2.Address.GOAL_POSITION, goal
            )
        result, error = self.packet.write1ByteTxRx(self.port, servo, dxl2.Address.TORQUE_ENABLE, 1)
        return error if result == COMM_SUCCESS else None

    def write_goals(self, ids: Sequence[int], goals: Sequence[int], speeds: Sequence[int]) -> int:
        """Every servo's Profile Velocity and Goal Position in one Sync Write; the SDK's
        result."""
        group = GroupSyncWrite(self.port, self.packet, dxl2.Address.PROFILE_VELOCITY, 8)
        for servo, goal, speed in zip(ids, goals, speeds, strict=True):
            group.addParam(servo, [*dxl2.value(speed, 4), *dxl2.value(goal, 4)])
        return group.txPacket()


BUSES: dict[int, type[AXBus] | type[XBus]] = {1: AXBus, 2: XBus}
"""The bus of each protocol version a profile may name."""
