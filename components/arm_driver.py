"""The arm driver: Dynamixel servos, one per joint of the robot's arm, through ROBOTIS's
dynamixel-sdk: AX-18A on protocol 1.0 (``protocol: 1``, the default) or X-series (XM430,
XL430) on protocol 2.0 (``protocol: 2``; ``components.servo_bus`` holds what differs). Which
servo drives which joint, from which zero and which way, is the robot description's
``servos:`` section (``wbc.servo_map``: servo angle = offset +
direction * q); the ``ids`` parameter, when set, overrides its ids.

Every 1/``rate_hz`` s it reads each servo's present position and speed (on protocol 2.0 all in
one Sync Read; on its own when that is not whole, and always on protocol 1.0, so that a fault
is named for its servo) and publishes ``arm/joint_states``.

A velocity command is checked (every entry finite, else the arm holds) and each joint's speed
clamped to the robot's velocity limit. It becomes, per joint, a goal position ahead of the
present one in the direction of motion (``lookahead_s`` of the commanded speed, at least
``min_step`` units) at the commanded speed (Moving Speed, 0.111 rpm per unit, or Profile
Velocity, 0.229 rpm per unit). A joint whose speed rounds to 0 (which would mean full speed)
holds: its goal is its position read when it stops (not a reading from before: a joint still
moving would move back to it after the stop), kept while it stays stopped, so it does not
creep. All the goals and speeds go in one Sync Write, and every goal written lies inside the
robot description's joint limits (the goals: ``components.arm_goals``). With no command for
``command_timeout_s`` the arm holds.

Each answer is checked (the protocol's ``status_fault``): a servo that is silent (for the SDK's
packet timeout, or ``answer_timeout_s`` when that is longer), or answers a truncated packet, a
bad checksum, another servo's id or the wrong length, is counted by that name
(``servo_faults.<name>``); a reading outside the joint limits (by more than ``limit_margin``)
is counted (``out_of_limits``) and never published. Either way no joint state is published,
the arm holds (each joint where it is read then, a faulty one at its last good reading) and
refuses commands until every servo answers again with a reading inside its limits, and the
component's state says why (``holding: servo 3 silent``); then every goal is set where its
joint is and torque is enabled again on every servo. Status-packet errors are counted by name
(``servo_error.<name>``: protocol 1.0's error bits; protocol 2.0's error number and, with the
alert bit, the bits of Hardware Error Status) and logged.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence

from dynamixel_sdk import COMM_SUCCESS

from components.arm_goals import ArmGoals
from components.joint_check import joints_match
from components.params import Param, ParamError
from components.process_entry import run_component
from components.pubsub import Input
from components.robot_vector import RobotVector, of_robot
from components.runtime import Component, Node
from components.servo_bus import BUSES, HOLD_SPEED, Reading, open_port
from components.stop_latch import StopLatch
from messages import topics
from messages.commands import ArmCommand
from messages.joints import JointStates
from protocols.dynamixel_v1 import StatusFault
from wbc.robot import BASE_DOF, MobileManipulator
from wbc.servo_map import ServoMap


def check_ids(ids: tuple[int, ...]) -> None:
    """``ParamError`` unless the servo ids are distinct and in 0..253."""
    if len(set(ids)) != len(ids) or not all(0 <= i < 254 for i in ids):
        raise ParamError(f"ids: expected distinct servo ids in 0..253, got {ids}")


class ArmDriver(Component):
    """arm/command in, arm/joint_states out, over the servos' serial bus."""

    reads = (Input(topics.ARM_COMMAND),)
    writes = (topics.ARM_JOINT_STATES,)
    params = (
        Param("port", str, "/dev/ttyUSB1", doc="serial port of the servo bus"),
        Param("baud", int, 1_000_000, low=9600, high=3_000_000, doc="bus speed, bit/s"),
        Param(
            "protocol",
            int,
            1,
            low=1,
            high=2,
            doc="Dynamixel protocol: 1 (AX-series) or 2 (X-series in position mode)",
        ),
        RobotVector(
            "ids",
            tuple,
            (),
            integers=True,
            optional=True,
            doc="a servo id per arm joint; [] takes the robot description's servos.ids",
            can_take=check_ids,
        ),
        Param("rate_hz", float, 50.0, low=1.0, high=200.0, doc="joint state rate"),
        Param(
            "command_timeout_s",
            float,
            0.2,
            low=0.01,
            high=10.0,
            doc="hold the arm after this long without a command, s",
        ),
        Param(
            "lookahead_s",
            float,
            0.25,
            low=0.01,
            high=5.0,
            doc="a goal is this many seconds of motion ahead",
        ),
        Param("min_step", int, 8, low=1, high=100, doc="least goal step ahead, units"),
        Param(
            "limit_margin",
            float,
            0.02,
            low=0.0,
            high=0.5,
            doc="a reading this far outside a joint limit is refused, rad",
        ),
        Param(
            "answer_timeout_s",
            float,
            0.0,
            low=0.0,
            high=5.0,
            doc="least wait for a servo's answer, s; the SDK's when longer (34 ms at 1 Mbit/s)",
        ),
    )

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        if node.profile.robot is None:
            raise ParamError("the arm driver needs the profile's `robot`")
        robot = MobileManipulator.from_yaml(node.profile.robot)
        self.low, self.high = robot.q_min[BASE_DOF:], robot.q_max[BASE_DOF:]
        self.speed_max = robot.velocity_max[BASE_DOF:]
        self.names, joints = robot.joint_names, robot.arm_dof
        servos = ServoMap.of(node.profile.robot, joints)
        if node.params["ids"]:
            names = ", ".join(self.names)
            servos = servos.with_ids(of_robot("ids", node.params["ids"], joints, names))
        self.servos = servos
        self.ids = servos.ids
        bus = self.bus = BUSES[node.params["protocol"]](
            str(node.params["port"]), node.params["answer_timeout_s"]
        )
        self.port = bus.port
        self.goals = ArmGoals(servos, bus, self.low, self.high, node.params)
        self.connected = False
        for name in (
            "sync_writes",
            "holds",
            "reads",
            "out_of_limits",
            "non_finite_commands",
            "speed_limited",
            "refused_commands",
            "port_errors",
        ):
            node.counters[name] = 0
        for fault in StatusFault:
            node.counters[f"servo_faults.{fault}"] = 0
        for name in bus.error_names:
            node.counters[f"servo_error.{name}"] = 0
        self.present: list[float | None] = [None] * joints
        """The last good reading of each joint (inside its limits)."""
        self.fault = ""
        """Why the arm holds whatever it is told; empty when every servo answers well."""
        self.holding = True
        self.output = node.publisher(topics.ARM_JOINT_STATES)
        self.timeout = node.alarm(self.hold)
        self._connect()  # a port that is not there yet is opened by the timer when it is
        self.latch = StopLatch(node, lambda state: self.hold() if state.stopped else None)
        node.subscribe(topics.ARM_COMMAND, self.on_command)
        node.timer(1.0 / node.params["rate_hz"], self.read_joints)

    def _connect(self) -> None:
        """Open the bus and enable every servo's torque; ``no port`` until it opens."""
        if not open_port(self.port, self.node.params["baud"]):
            self.node.state = "no port"
            return
        self.connected = True
        self.node.state = "running"
        try:
            self._enable_torque()
        except (OSError, TypeError) as error:  # the port went away under the SDK
            self._lost(error)

    def _enable_torque(self) -> None:
        """Torque on for every servo (a servo that browned out comes back with it off)."""
        for servo in self.ids:
            error = self.bus.enable_torque(servo)
            if error is not None:
                self._count_errors(servo, error)

    def _lost(self, error: Exception) -> None:
        self.node.count("port_errors")
        self.node.warn("port_errors", f"lost {self.node.params['port']}: {error}")
        self.connected = False
        self.node.state = "no port"
        try:
            self.port.closePort()
        except OSError:
            pass

    def _read(self, servo: int, read: Reading | None = None) -> tuple[int, float] | StatusFault:
        """One servo's Present Position (units) and speed (rad/s), or what is wrong: ``read``
        when a read of all the servos gave it, else read now."""
        reading, fault, error = self.bus.read(servo) if read is None else read
        if fault is not None:
            self.node.count(f"servo_faults.{fault}")
            self.node.warn(f"servo_faults.{fault}.{servo}", f"servo {servo}: {fault} answer")
            return fault
        self._count_errors(servo, error)
        assert reading is not None
        return reading

    def _count_errors(self, servo: int, error: int) -> None:
        if not error:
            return
        for name in self.bus.errors(servo, error):
            self.node.count(f"servo_error.{name}")
            self.node.warn(f"servo_error.{name}", f"servo {servo} reports {name}")

    def read_joints(self) -> None:
        """Timer: each servo's present position and speed; publish when all answered well,
        else hold and say why."""
        if not self.connected:
            self._connect()
            return
        readings, faults = [], {}
        try:
            batch = self.bus.read_all(self.ids)
            for index in range(len(self.ids)):
                reading = self._reading(index, None if batch is None else batch[index])
                if isinstance(reading, str):
                    faults[index] = reading
                else:
                    readings.append(reading)
        except (OSError, TypeError) as error:  # the port went away under the SDK
            self._lost(error)
            return
        self.node.count("reads", len(readings))
        if faults:
            self._hold_for("; ".join(faults.values()), faults.keys())
            return
        if self.fault:
            self._recover()
        self.output.put(
            JointStates(
                header=self.node.header("arm", None, self.output.next_seq),
                names=self.names,
                positions=tuple(p for p, _ in readings),
                velocities=tuple(v for _, v in readings),
            )
        )

    def _reading(self, index: int, read: Reading | None = None) -> tuple[float, float] | str:
        """Joint ``index``'s position (kept as ``present``) and speed, read now (or ``read``
        by a read of all); or what is wrong: a fault, or a position outside the joint's
        limits."""
        servo = self.ids[index]
        reading = self._read(servo, read)
        if isinstance(reading, StatusFault):
            return f"servo {servo} {reading}"
        units, speed = reading
        position = self.servos.joint_position(index, self.bus.angle_of_units(units))
        low, high = self.low[index], self.high[index]
        margin = self.node.params["limit_margin"]
        if not low - margin <= position <= high + margin:
            self.node.count("out_of_limits")
            return (
                f"servo {servo} reads {position:.3f} rad, outside its limits "
                f"[{low:.3f}, {high:.3f}]"
            )
        self.present[index] = position
        return position, self.servos.directions[index] * speed

    def _recover(self) -> None:
        """Every servo answers again: goals where the joints are now, then torque on."""
        self.node.warn("holding", f"every servo answers again (was: {self.fault})")
        self.fault = ""
        self.node.state = "running"
        self.goals.held = [None] * len(self.ids)
        self.hold()
        self._enable_torque()

    def _hold_for(self, why: str, failed: Collection[int]) -> None:
        if why != self.fault:
            self.node.warn("holding", f"arm holding: {why}")
        self.fault = why
        self.node.state = f"holding: {why}"
        self.hold(failed)

    def on_command(self, command: ArmCommand) -> None:
        """Goals ahead of the present positions at the commanded speeds, in one Sync Write."""
        if not joints_match(
            self.node, "refused_commands", "arm/command", command.joint_names, self.names
        ):
            self.hold()
            return
        velocities = command.joint_velocities
        if len(velocities) != len(self.ids) or not all(math.isfinite(v) for v in velocities):
            self.node.count("non_finite_commands")
            self.node.warn(
                "non_finite_commands",
                f"expected {len(self.ids)} finite joint velocities, got {velocities}; holding",
            )
            self.hold()
            return
        if self.latch.refuses():
            return  # the arm held where it was when the stop came
        if self.fault or not self.connected or any(p is None for p in self.present):
            self.node.count("refused_commands")
            return  # holding, or no position read yet to aim from
        limited = []
        for index, velocity in enumerate(velocities):
            limit = self.speed_max[index]
            if abs(velocity) > limit:
                self.node.count("speed_limited")
                velocity = math.copysign(limit, velocity)
            limited.append(velocity)
        self._read_stopping([i for i, v in enumerate(limited) if self.bus.speed_units(v) is None])
        present = self.present
        aims = (self.goals.ahead(i, v, present[i]) for i, v in enumerate(limited))
        goals, speeds = zip(*aims, strict=True)
        self.holding = False
        self._sync_write(goals, speeds)
        self.timeout.set(self.node.params["command_timeout_s"])

    def _read_stopping(self, joints: Sequence[int], failed: Collection[int] = ()) -> None:
        """Read the ``joints`` that start to hold now (``present``), but those whose servo has
        just ``failed`` to answer; read again those read before a servo that failed now (its
        timeout passed since). A reading of the last cycle, or from before a timeout, lies
        behind a joint still moving: held there, it moved back after the stop."""
        stopping = [i for i in joints if self.goals.held[i] is None and i not in failed]
        try:
            answered = [not isinstance(self._reading(i), str) for i in stopping]
            if False in answered:
                last = len(answered) - 1 - answered[::-1].index(False)
                for index, ok in zip(stopping[:last], answered[:last], strict=True):
                    if ok:
                        self._reading(index)
        except (OSError, TypeError) as error:  # the port went away under the SDK
            self._lost(error)

    def hold(self, failed: Collection[int] = ()) -> None:
        """Every joint's goal where it stopped, slowly: the arm stops where it is. Written again
        at each call, so a lost Sync Write is made good. A joint that starts to hold is read
        first (``_read_stopping``; not a servo that has just ``failed``: no second timeout
        while the others move on)."""
        if not self.connected or any(p is None for p in self.present):
            return
        if not self.holding:
            self.holding = True
            self.node.count("holds")
        self.timeout.cancel()
        joints = range(len(self.ids))
        self._read_stopping(joints, failed)
        goals = [self.goals.holding(i, self.present[i]) for i in joints]
        self._sync_write(goals, [HOLD_SPEED] * len(joints))

    def _sync_write(self, goals: Sequence[int], speeds: Sequence[int]) -> None:
        if not self.connected:  # a read on the way found the port gone
            return
        self.goals.check(self.ids, goals, speeds)
        try:
            result = self.bus.write_goals(self.ids, goals, speeds)
        except (OSError, TypeError) as error:
            self._lost(error)
            return
        if result != COMM_SUCCESS:
            self.node.warn("sync_write", f"sync write: {self.bus.result_text(result)}")
        self.node.count("sync_writes")

    def shutdown(self) -> None:
        """Hold the arm where it is, then close the port."""
        if self.connected:
            self.hold()
            self.port.closePort()


if __name__ == "__main__":
    run_component(ArmDriver)
