"""The serial devices of `parsimony doctor`: the arm's servos (Dynamixel protocol 1.0 or 2.0)
and the Create, asked what they are without moving anything.

Only Ping and Read go to a servo (never a write: torque, goals and tables stay as they are);
only Sensors (142) goes to the Create, and Start (128) when it does not answer, which puts an
OI that is off in Passive, where nothing moves. A servo silent at its id and baud rate is
looked for at the other ids (protocol 2.0: one broadcast Ping) and at the other baud rates, so
that the line says where it is.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import serial

from protocols import create_oi as oi
from protocols import dynamixel_v1 as dxl1
from protocols import dynamixel_v2 as dxl2
from protocols.dynamixel_v1 import StatusFault

ANSWER_TIMEOUT_S = 0.1
"""How long an answer is awaited (a U2D2's USB latency is up to 16 ms, the Create's 15 ms)."""
SCAN_TIMEOUT_S = 0.02
"""How long each id of a scan for a servo at another id is awaited."""
BAUDS = (1_000_000, 57_600, 115_200, 2_000_000, 3_000_000, 9_600)
"""The baud rates a servo silent at the profile's is looked for at."""
MODELS = {
    12: "AX-12A",
    18: "AX-18A",
    300: "AX-12W",
    29: "MX-28",
    310: "MX-64",
    320: "MX-106",
    1000: "XH430-W350",
    1010: "XH430-W210",
    1020: "XM430-W350",
    1030: "XM430-W210",
    1060: "XL430-W250",
    1070: "XC430-W150",
    1080: "XC430-W240",
    1120: "XM540-W270",
    1130: "XM540-W150",
    1190: "XL330-M077",
    1200: "XL330-M288",
}
"""Dynamixel model numbers (Model Number, address 0) by name."""
DRIVEN = {1: (12, 18, 300), 2: (1000, 1010, 1020, 1030, 1060, 1070, 1080, 1120, 1130, 1190, 1200)}
"""The models the arm driver drives on each protocol: protocol 1.0 the AX series' control table
and units (1024 steps over 300 degrees), 2.0 the X series' (4096 steps a turn)."""
BATTERY_LOW = 0.2
"""A Create charged below this fraction is a warning."""


@dataclass(frozen=True)
class Check:
    """One line of the checklist: ``status`` ok, warn or fail; ``fix`` what to do, when not ok."""

    name: str
    status: str
    detail: str
    fix: str = ""

    def json(self) -> dict[str, str]:
        return {"name": self.name, "status": self.status, "detail": self.detail, "fix": self.fix}


def model_name(number: int) -> str:
    return MODELS.get(number, f"model {number}")


class Bus:
    """A servo bus opened at ``baud`` for Pings and Reads of one protocol (1 or 2)."""

    def __init__(self, port: str, baud: int, protocol: int, answer_timeout_s: float = 0.0) -> None:
        """``answer_timeout_s``: the least wait for an expected servo's answer (the arm
        driver's parameter: an emulated chain's may come late, and late is not silent)."""
        self.serial = serial.Serial(port, baud, timeout=0.002)
        self.answer_timeout_s = max(ANSWER_TIMEOUT_S, answer_timeout_s)
        self.protocol = protocol
        self.dxl = dxl1 if protocol == 1 else dxl2

    def close(self) -> None:
        self.serial.close()

    def set_baud(self, baud: int) -> None:
        self.serial.baudrate = baud

    def _answers(self, packet: bytes, count: int, timeout_s: float) -> list[bytes]:
        """Up to ``count`` whole status packets that come back for ``packet`` in time."""
        self.serial.reset_input_buffer()
        self.serial.write(packet)
        buffer, answers = b"", []
        deadline = time.monotonic() + timeout_s
        header = self.dxl.HEADER
        while len(answers) < count and time.monotonic() < deadline:
            buffer += self.serial.read(256)
            start = buffer.find(header)
            if start < 0:
                continue
            buffer = buffer[start:]
            fault = self.dxl.status_fault(buffer, buffer[len(header)], -1)
            if fault is StatusFault.TRUNCATED:
                continue
            length = buffer[3] + 4 if self.protocol == 1 else dxl2.packet_end(buffer)
            if fault is not StatusFault.CHECKSUM:
                answers.append(buffer[:length])
            buffer = buffer[length:]
        return answers

    def ping(self, servo: int, timeout_s: float | None = None) -> bool:
        """Whether ``servo`` answers a Ping within ``timeout_s`` (None: an expected servo's
        wait)."""
        packet = self.dxl.instruction_packet(servo, self.dxl.Instruction.PING)
        wait = self.answer_timeout_s if timeout_s is None else timeout_s
        return any(a[len(self.dxl.HEADER)] == servo for a in self._answers(packet, 1, wait))

    def broadcast_ping(self, timeout_s: float = ANSWER_TIMEOUT_S) -> list[int]:
        """Protocol 2.0: the ids of every servo that answers a broadcast Ping."""
        packet = dxl2.instruction_packet(dxl2.BROADCAST_ID, dxl2.Instruction.PING)
        return sorted(a[4] for a in self._answers(packet, 253, timeout_s))

    def read(self, servo: int, address: int, length: int) -> bytes | None:
        """``length`` bytes of the control table from ``address``; None without an answer."""
        if self.protocol == 1:
            packet = dxl1.instruction_packet(servo, dxl1.Instruction.READ, bytes((address, length)))
        else:
            packet = dxl2.read(servo, address, length)
        for answer in self._answers(packet, 1, self.answer_timeout_s):
            if self.dxl.status_fault(answer, servo, length) is None:
                return answer[5:-1] if self.protocol == 1 else dxl2.status_data(answer)[1]
        return None

    def find_elsewhere(self, missing: Sequence[int], known: Sequence[int]) -> list[int]:
        """Ids other than ``known`` that answer (as many as ``missing`` at most)."""
        if self.protocol == 2:
            return [i for i in self.broadcast_ping() if i not in known]
        found: list[int] = []
        for servo in range(dxl1.BROADCAST_ID):
            if len(found) == len(missing):
                break
            if servo not in known and self.ping(servo, SCAN_TIMEOUT_S):
                found.append(servo)
        return found

    def find_baud(self, ids: Sequence[int], profile_baud: int) -> int | None:
        """The first other baud rate at which one of ``ids`` answers; the bus is left at the
        profile's."""
        try:
            for baud in BAUDS:
                if baud == profile_baud:
                    continue
                self.set_baud(baud)
                if any(self.ping(i, ANSWER_TIMEOUT_S) for i in ids):
                    return baud
            return None
        finally:
            self.set_baud(profile_baud)


@dataclass(frozen=True)
class Joint:
    """A joint's servo as the profile expects it: its name, id and Goal Positions' range."""

    name: str
    id: int
    low: int
    high: int


def _servo_line(bus: Bus, joint: Joint, baud: int) -> Check:
    name = f"servo {joint.id} ({joint.name})"
    if bus.protocol == 1:
        table = bus.read(joint.id, 0, 25)
        if table is None:
            return Check(name, "fail", "answers a Ping but not a Read", "check its cable")
        model, torque = int.from_bytes(table[0:2], "little"), table[dxl1.Address.TORQUE_ENABLE]
        low = int.from_bytes(table[6:8], "little")
        high = int.from_bytes(table[8:10], "little")
        hardware_error, operating = 0, ""
    else:
        table = bus.read(joint.id, 0, 71)
        if table is None:
            return Check(name, "fail", "answers a Ping but not a Read", "check its cable")
        model, torque = int.from_bytes(table[0:2], "little"), table[dxl2.Address.TORQUE_ENABLE]
        high = dxl2.signed(table[48:52])
        low = dxl2.signed(table[52:56])
        hardware_error = table[dxl2.Address.HARDWARE_ERROR_STATUS]
        mode = table[dxl2.Address.OPERATING_MODE]
        modes = {m.value: m.name.lower() for m in dxl2.OperatingMode}
        operating = f", {modes.get(mode, f'operating mode {mode}')} mode"
    what = f"{model_name(model)} at {baud} baud, protocol {bus.protocol}.0"
    if model not in DRIVEN[bus.protocol]:
        driven = ", ".join(model_name(m) for m in DRIVEN[bus.protocol][:3])
        return Check(
            name,
            "fail",
            f"{what}: the arm driver's protocol {bus.protocol} drives {driven}...",
            "fit the robot's servo here, or set arm_driver's protocol to this servo's",
        )
    limits = f"angle limits {low}..{high}"
    torque_text = "torque on (holding)" if torque else "torque off"
    detail = f"{what}, {limits}{operating}, {torque_text}"
    if hardware_error:
        bits = [bit.name.lower() for bit in dxl2.HardwareError if hardware_error & bit]
        return Check(
            name,
            "fail",
            f"{detail}; hardware error: {', '.join(bits)}",
            "remove the cause, then power the servo off and on (or reboot it)",
        )
    if low > joint.low or high < joint.high:
        return Check(
            name,
            "warn",
            f"{detail}: they do not cover the joint's {joint.low}..{joint.high}, "
            "so the servo stops short of the joint's limits",
            "widen the servo's angle limits (Dynamixel Wizard) or narrow the joint's",
        )
    return Check(name, "ok", f"{detail} (the joint's {joint.low}..{joint.high} inside)")


def servo_checks(
    port: str, baud: int, protocol: int, joints: Sequence[Joint], answer_timeout_s: float = 0.0
) -> list[Check]:
    """A line per servo of the arm on ``port`` (opened already: the port's own line says why
    not), each awaited ``answer_timeout_s`` at least (``Bus``)."""
    try:
        bus = Bus(port, baud, protocol, answer_timeout_s)
    except (OSError, ValueError) as error:
        return [Check("servos", "fail", f"cannot open {port}: {error}", "see the port's line")]
    try:
        silent = [j for j in joints if not bus.ping(j.id)]
        lines = [_servo_line(bus, j, baud) for j in joints if j not in silent]
        if silent:
            lines += _silent_lines(bus, silent, [j.id for j in joints], baud)
        return lines
    finally:
        bus.close()


def _silent_lines(bus: Bus, silent: list[Joint], ids: list[int], baud: int) -> list[Check]:
    """Where the servos that did not answer are: when none did, at another baud rate; else at
    another id; or nowhere."""
    missing = [j.id for j in silent]
    other_baud = bus.find_baud(missing, baud) if len(silent) == len(ids) else None
    elsewhere = [] if other_baud else bus.find_elsewhere(missing, ids)
    lines = []
    for joint in silent:
        name, expected = f"servo {joint.id} ({joint.name})", f"id {joint.id} at {baud} baud"
        if elsewhere:
            found = ", ".join(map(str, elsewhere))
            answer = f"id {found} answers" if len(elsewhere) == 1 else f"ids {found} answer"
            lines.append(
                Check(
                    name,
                    "fail",
                    f"no answer at {expected}; {answer} instead",
                    f"set that servo's id to {joint.id} (Dynamixel Wizard), or the robot's "
                    "servos.ids (or arm_driver's ids) to the ids the servos have",
                )
            )
        elif other_baud is not None:
            lines.append(
                Check(
                    name,
                    "fail",
                    f"no answer at {expected}; the servos answer at {other_baud} baud",
                    f"set arm_driver's baud: {other_baud}, or the servos' baud rate to {baud} "
                    "(Dynamixel Wizard)",
                )
            )
        else:
            lines.append(
                Check(
                    name,
                    "fail",
                    f"no answer at {expected}, nor at any other id or baud rate",
                    "check the servo's power (12 V) and its cable to the bus adapter",
                )
            )
    return lines


def create_check(port: str) -> list[Check]:
    """The Create's lines: it answers, its OI mode and its battery's charge."""
    try:
        link = serial.Serial(port, oi.BAUD, timeout=0.002)
    except (OSError, ValueError) as error:
        return [Check("create", "fail", f"cannot open {port}: {error}", "see the port's line")]
    try:
        mode = _sensor(link, oi.OI_MODE)
        started = ""
        if mode is None:
            link.write(bytes([oi.START]))
            mode = _sensor(link, oi.OI_MODE)
            started = " (its OI was off: Start put it in Passive, where nothing moves)"
        if mode is None or mode >= len(oi.OI_MODES):
            return [
                Check(
                    "create",
                    "fail",
                    f"no answer on {port} at {oi.BAUD} baud",
                    "turn the Create on (press Clean), dock or charge it, and check the cable",
                )
            ]
        charge, capacity = _sensor(link, oi.BATTERY_CHARGE), _sensor(link, oi.BATTERY_CAPACITY)
    finally:
        link.close()
    lines = [Check("create", "ok", f"answers, OI mode {oi.OI_MODES[mode]}{started}")]
    if charge is None or not capacity:
        lines.append(Check("create battery", "warn", "no charge reading", "check the cable"))
    else:
        fraction = charge / capacity
        status = "ok" if fraction >= BATTERY_LOW else "warn"
        fix = "" if status == "ok" else "charge the Create (dock it)"
        detail = f"{100 * fraction:.0f} % ({charge} of {capacity} mAh)"
        lines.append(Check("create battery", status, detail, fix))
    return lines


def _sensor(link: serial.Serial, packet_id: int) -> int | None:
    """Packet ``packet_id``'s value, None when it did not come whole in time."""
    length = oi.PACKET_LENGTHS[packet_id]
    link.reset_input_buffer()
    link.write(oi.sensors(packet_id))
    data = b""
    deadline = time.monotonic() + ANSWER_TIMEOUT_S
    while len(data) < length and time.monotonic() < deadline:
        data += link.read(length - len(data))
    return int.from_bytes(data, "big") if len(data) == length else None
