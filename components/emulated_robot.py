"""The simulator with its robot behind serial devices: an emulated Create 2 and an emulated
chain of Dynamixel servos, one per joint of the robot's arm (placed as its description's
``servos:`` say; AX-18A on protocol 1.0, or X-series on protocol 2.0 with ``servo_protocol:
2``), each on a pseudo-terminal, moving the simulated world.

Everything of ``components.simulator`` but the sensor topics: the world, the ceiling camera,
``sim/clock`` and ``sim/truth``. The base and arm drivers open the emulators' ports (at the
symbolic links ``create_link`` and ``servo_link``) as they open the real robot's, speak its
protocols byte for byte, and publish the odometry and joint states themselves. As on the real
robot, nothing here stops the wheels when commands stop: the drivers must.

It runs in real time only: a serial line carries no stamps, so the simulator cannot tell which
of its steps a driver's odometry answers, and lockstep is acknowledged by stamps.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from pathlib import Path

from components.params import Param, ParamError, load_robot
from components.process_entry import run_component
from components.runtime import Node
from components.simulator import Simulator
from messages import topics
from sim2d.devices.ax_servos import AXChainEmulator
from sim2d.devices.create2 import Create2Emulator
from sim2d.devices.x_servos import XChainEmulator
from sim2d.world import World
from wbc.servo_map import ServoMap


class WorldDevices:
    """The emulators' view of the world (both backends): wheel speeds and servo velocities
    in, encoder counts and servo angles out, under one lock against the stepping thread. The
    servos map to the joints as the robot description's ``servos`` say (``wbc.servo_map``)."""

    def __init__(self, world: World, servos: ServoMap) -> None:
        self.world, self.servos = world, servos
        self.lock = threading.Lock()
        self.wheels = (0.0, 0.0)
        self.joints = (0.0,) * world.robot.arm_dof

    def set_wheel_speeds(self, left: float, right: float) -> None:
        with self.lock:
            self.wheels = (left, right)

    def encoder_counts(self) -> tuple[int, int]:
        with self.lock:
            return self.world.encoder_counts

    def joint_positions(self) -> Sequence[float]:
        """The servos' angles (rad), one per joint."""
        with self.lock:
            q = self.world.q[3:].tolist()
        return tuple(self.servos.servo_angle(i, v) for i, v in enumerate(q))

    def set_joint_velocities(self, velocities: Sequence[float]) -> None:
        """The servos' velocities (rad/s), one per joint."""
        joints = tuple(d * v for d, v in zip(self.servos.directions, velocities, strict=True))
        with self.lock:
            self.joints = joints


class EmulatedRobot(Simulator):
    """The simulator whose robot answers on serial ports (see the module docstring)."""

    reads = ()
    writes = (topics.SIM_CLOCK, topics.CAMERA_IMAGE, topics.SIM_TRUTH)
    params = (
        *(p for p in Simulator.params if p.name != "command_timeout_s"),
        Param("create_link", str, "/tmp/parsimony/create2", doc="link to the Create's port"),
        Param("servo_link", str, "/tmp/parsimony/servos", doc="link to the servos' port"),
        Param(
            "servo_protocol",
            int,
            1,
            low=1,
            high=2,
            doc="the servos' Dynamixel protocol: 1 (AX-18A) or 2 (X-series)",
        ),
    )

    def __init__(self, node: Node) -> None:
        if node.params["lockstep"]:
            raise ParamError("lockstep: a serial line carries no stamps; run in real time")
        if node.params["real_time_factor"] != 1.0 or not node.params["host_epoch"]:
            raise ParamError(
                "real_time_factor: the drivers keep the host's time; the emulated "
                "robot runs at 1.0 with host_epoch true"
            )
        kind = load_robot(node.profile.robot).base.kind if node.profile.robot else "differential"
        if kind != "differential":
            raise ParamError(
                f"robot: the emulated Create 2 drives a differential base, not the {kind} base "
                f"of {node.profile.robot}"
            )
        super().__init__(node)
        servos = ServoMap.of(node.profile.robot, self.robot.arm_dof)
        self.devices = WorldDevices(self.world, servos)
        links = [Path(str(node.params[name])) for name in ("create_link", "servo_link")]
        for link in links:
            link.parent.mkdir(parents=True, exist_ok=True)
        self.create = Create2Emulator(self.devices, links[0])
        chain = XChainEmulator if node.params["servo_protocol"] == 2 else AXChainEmulator
        self.servos = chain(self.devices, servos.ids, link=links[1])
        self.create.start()
        self.servos.start()
        for name in ("create_bad_bytes", "servo_bad_checksums"):
            node.counters[name] = 0

    def step(self) -> None:
        """The servos steer towards their goals, then the world steps with what the devices
        were last told."""
        self.servos.update(self.step_ns / 1e9)
        with self.devices.lock:
            self.world.command(*self.devices.wheels, self.devices.joints)
        super().step()
        self.node.counters["create_bad_bytes"] = self.create.counters.get("bad_bytes", 0)
        self.node.counters["servo_bad_checksums"] = self.servos.counters.get("bad_checksums", 0)

    def _apply_commands(self) -> None:
        """The devices command the world (see ``step``)."""

    def shutdown(self) -> None:
        self.create.stop()
        self.servos.stop()


if __name__ == "__main__":
    run_component(EmulatedRobot)
