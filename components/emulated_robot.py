"""The simulator with its robot behind serial devices: an emulated Create 2 and an emulated
chain of five AX-18A servos, each on a pseudo-terminal, moving the simulated world.

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

from components.params import Param, ParamError
from components.process_entry import run_component
from components.runtime import Node
from components.simulator import Simulator
from messages import topics
from sim2d.devices.ax_servos import AXChainEmulator
from sim2d.devices.create2 import Create2Emulator
from sim2d.world import World


class WorldDevices:
    """The emulators' view of the world (both backends): wheel speeds and joint velocities
    in, encoder counts and joint angles out, under one lock against the stepping thread."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.lock = threading.Lock()
        self.wheels = (0.0, 0.0)
        self.joints = (0.0,) * 5

    def set_wheel_speeds(self, left: float, right: float) -> None:
        with self.lock:
            self.wheels = (left, right)

    def encoder_counts(self) -> tuple[int, int]:
        with self.lock:
            return self.world.encoder_counts

    def joint_positions(self) -> Sequence[float]:
        with self.lock:
            return tuple(self.world.q[3:].tolist())

    def set_joint_velocities(self, velocities: Sequence[float]) -> None:
        with self.lock:
            self.joints = tuple(velocities)


class EmulatedRobot(Simulator):
    """The simulator whose robot answers on serial ports (see the module docstring)."""

    reads = ()
    writes = (topics.SIM_CLOCK, topics.CAMERA_IMAGE, topics.SIM_TRUTH)
    params = (
        *(p for p in Simulator.params if p.name != "command_timeout_s"),
        Param("create_link", str, "/tmp/parsimony/create2", doc="link to the Create's port"),
        Param("servo_link", str, "/tmp/parsimony/servos", doc="link to the servos' port"),
    )

    def __init__(self, node: Node) -> None:
        if node.params["lockstep"]:
            raise ParamError("lockstep: a serial line carries no stamps; run in real time")
        if node.params["real_time_factor"] != 1.0 or not node.params["host_epoch"]:
            raise ParamError(
                "real_time_factor: the drivers keep the host's time; the emulated "
                "robot runs at 1.0 with host_epoch true"
            )
        super().__init__(node)
        self.devices = WorldDevices(self.world)
        links = [Path(str(node.params[name])) for name in ("create_link", "servo_link")]
        for link in links:
            link.parent.mkdir(parents=True, exist_ok=True)
        self.create = Create2Emulator(self.devices, links[0])
        self.servos = AXChainEmulator(self.devices, link=links[1])
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
