"""The arm driver: five AX-18A servos, Dynamixel protocol 1.0, through ROBOTIS's dynamixel-sdk.

Every 1/``rate_hz`` s it reads each servo's present position, speed and load on its own (bulk
and sync read do not exist for AX servos in protocol 1.0) and publishes ``arm/joint_states``.

A velocity command becomes, per joint, a goal position ahead of the present one in the
direction of motion (``lookahead_s`` of the commanded speed, at least ``min_step`` units),
clamped to the robot's joint limits, with the moving speed of the commanded speed (about 0.111
rpm per unit). A moving speed of 0 means full speed to the servo, so a joint commanded to stop
holds: its goal is its present position. All five goals and speeds go in one Sync Write. With
no command for ``command_timeout_s`` the arm holds.

Status-packet error bits are counted by name (``servo_error.<bit>``) and logged; a servo that
stops answering is counted (``servo_timeouts``), the arm holds, no joint state is published
until every servo answers again, and the component's state says ``servo <id> silent``.
"""

from __future__ import annotations

import math

from dynamixel_sdk import COMM_SUCCESS, GroupSyncWrite, PacketHandler, PortHandler

from components.params import Param, ParamError
from components.process_entry import run_component
from components.pubsub import Input
from components.runtime import Component, Node
from messages import topics
from messages.base import ARM_JOINTS
from messages.commands import ArmCommand
from messages.joints import JointStates
from protocols import dynamixel_v1 as dxl
from wbc.robot import MobileManipulator

JOINT_NAMES = tuple(f"q{i}" for i in range(1, ARM_JOINTS + 1))
ERROR_BITS = {int(bit): bit.name.lower() for bit in dxl.StatusError}
"""The status-packet error bits of protocol 1.0, by the name they are counted under."""


def ids_of(text: object) -> tuple[int, ...]:
    """``"1, 2, 3, 4, 5"`` as five servo ids, or ``ParamError``."""
    try:
        ids = tuple(int(v) for v in str(text).split(","))
    except ValueError as error:
        raise ParamError(f"ids: {error}") from error
    if len(ids) != ARM_JOINTS or len(set(ids)) != ARM_JOINTS or not all(0 <= i < 254 for i in ids):
        raise ParamError(f"ids: expected {ARM_JOINTS} distinct ids in 0..253, got {text!r}")
    return ids


class ArmDriver(Component):
    """arm/command in, arm/joint_states out, over the servos' serial bus."""

    reads = (Input(topics.ARM_COMMAND),)
    writes = (topics.ARM_JOINT_STATES,)
    params = (
        Param("port", str, "/dev/ttyUSB1", doc="serial port of the servo bus"),
        Param("baud", int, 1_000_000, low=9600, high=3_000_000, doc="bus speed, bit/s"),
        Param("ids", str, "1, 2, 3, 4, 5", doc="servo ids of q1..q5", can_take=ids_of),
        Param("rate_hz", float, 50.0, low=1.0, high=200.0, doc="joint state rate"),
        Param("command_timeout_s", float, 0.2, low=0.01, high=10.0,
              doc="hold the arm after this long without a command, s"),
        Param("lookahead_s", float, 0.25, low=0.01, high=5.0,
              doc="a goal is this many seconds of motion ahead"),
        Param("min_step", int, 8, low=1, high=100, doc="least goal step ahead, units"),
    )  # fmt: skip

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        if node.profile.robot is None:
            raise ParamError("the arm driver needs the profile's `robot`")
        robot = MobileManipulator.from_yaml(node.profile.robot)
        self.low, self.high = robot.q_min[3:], robot.q_max[3:]
        self.ids = ids_of(node.params["ids"])
        self.port = PortHandler(str(node.params["port"]))
        self.packet = PacketHandler(1.0)
        self.connected = False
        for name in ("servo_timeouts", "sync_writes", "holds", "reads"):
            node.counters[name] = 0
        for name in ERROR_BITS.values():
            node.counters[f"servo_error.{name}"] = 0
        self.present: list[float | None] = [None] * ARM_JOINTS
        self.last_command_ns: int | None = None
        self.holding = True
        self.output = node.publisher(topics.ARM_JOINT_STATES)
        self._connect()  # a port that is not there yet is opened by the timer when it is
        node.subscribe(topics.ARM_COMMAND, self.on_command)
        node.timer(1.0 / node.params["rate_hz"], self.read_joints)

    def _connect(self) -> None:
        """Open the bus and enable every servo's torque; ``no port`` until it opens."""
        try:
            opened = self.port.openPort() and self.port.setBaudRate(self.node.params["baud"])
        except OSError:  # pyserial's SerialException is one
            opened = False
        if not opened:
            self.node.state = "no port"
            return
        self.connected = True
        self.node.state = "running"
        for servo in self.ids:
            torque = self.packet.write1ByteTxRx(self.port, servo, dxl.Address.TORQUE_ENABLE, 1)
            self._check(servo, *torque)

    def _check(self, servo: int, result: int, error: int) -> bool:
        """Count a failed exchange or the error bits of a status packet; True when it went
        through (error bits included: the servo answered)."""
        if result != COMM_SUCCESS:
            self.node.count("servo_timeouts")
            self.node.warn(f"servo_timeout.{servo}",
                           f"servo {servo}: {self.packet.getTxRxResult(result)}")  # fmt: skip
            return False
        for bit, name in ERROR_BITS.items():
            if error & bit:
                self.node.count(f"servo_error.{name}")
                self.node.warn(f"servo_error.{name}", f"servo {servo} reports {name}")
        return True

    def read_joints(self) -> None:
        """Timer: each servo's present position and speed; publish when all answered."""
        if not self.connected:
            self._connect()
            return
        positions, velocities, silent = [], [], []
        for index, servo in enumerate(self.ids):
            data, result, error = self.packet.readTxRx(
                self.port, servo, dxl.Address.PRESENT_POSITION, 4
            )
            if not self._check(servo, result, error):
                silent.append(servo)
                continue
            self.node.count("reads")
            position = dxl.angle_of_units(data[0] | data[1] << 8)
            self.present[index] = position
            positions.append(position)
            velocities.append(dxl.rad_s_of_speed_units(data[2] | data[3] << 8))
        if silent:
            self.node.state = "servo " + ", ".join(map(str, silent)) + " silent"
            self.hold()
            return
        if self.node.state.startswith("servo"):
            self.node.state = "running"
        now = self.node.clock.monotonic_ns()
        timeout_ns = self.node.params["command_timeout_s"] * 1e9
        if not self.holding and (self.last_command_ns is None
                                 or now - self.last_command_ns > timeout_ns):  # fmt: skip
            self.hold()
        self.output.put(
            JointStates(
                header=self.node.header("arm", None, self.output.next_seq),
                names=JOINT_NAMES,
                positions=tuple(positions),
                velocities=tuple(velocities),
            )
        )

    def on_command(self, command: ArmCommand) -> None:
        """Goals ahead of the present positions at the commanded speeds, in one Sync Write."""
        velocities = command.joint_velocities
        if len(velocities) != ARM_JOINTS or not all(math.isfinite(v) for v in velocities):
            raise ValueError(f"expected {ARM_JOINTS} finite joint velocities, got {velocities}")
        if not self.connected or any(p is None for p in self.present):
            return  # no position read yet: nothing to aim from
        goals, speeds = [], []
        lookahead, min_step = self.node.params["lookahead_s"], self.node.params["min_step"]
        for index, velocity in enumerate(velocities):
            present = self.present[index]
            units = dxl.speed_units(abs(velocity))
            if units == 0:  # too slow to command: hold (0 would mean full speed)
                goals.append(dxl.position_units(present))
                speeds.append(1)
                continue
            step = max(abs(velocity) * lookahead, min_step / dxl.POSITION_UNITS_PER_RAD)
            goal = present + math.copysign(step, velocity)
            goal = min(max(goal, self.low[index]), self.high[index])
            goals.append(dxl.position_units(goal))
            speeds.append(units)
        self.last_command_ns = self.node.clock.monotonic_ns()
        self.holding = False
        self._sync_write(goals, speeds)

    def hold(self) -> None:
        """Every servo's goal at its present position, slowly: the arm stops where it is."""
        if any(p is None for p in self.present):
            return
        self.holding = True
        self.node.count("holds")
        self._sync_write([dxl.position_units(p) for p in self.present], [1] * ARM_JOINTS)

    def _sync_write(self, goals: list[int], speeds: list[int]) -> None:
        group = GroupSyncWrite(self.port, self.packet, dxl.Address.GOAL_POSITION, 4)
        for servo, goal, speed in zip(self.ids, goals, speeds, strict=True):
            group.addParam(servo, [goal & 0xFF, goal >> 8, speed & 0xFF, speed >> 8])
        result = group.txPacket()
        if result != COMM_SUCCESS:
            self.node.warn("sync_write", f"sync write: {self.packet.getTxRxResult(result)}")
        self.node.count("sync_writes")

    def shutdown(self) -> None:
        """Hold the arm where it is, then close the port."""
        if self.connected:
            self.hold()
            self.port.closePort()


if __name__ == "__main__":
    run_component(ArmDriver)
