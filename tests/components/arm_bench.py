"""What the arm driver's tests share, on either protocol: the emulated servo chain, the world
its joints move in, the driver's process, and the test as the controller."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from typing import Self

from messages import codec, topics
from messages.commands import ArmCommand
from messages.header import Header
from sim2d.devices.servo_chain import IntegratingJoints, ServoChain
from tests.components.conftest import System, _wait_until
from tests.components.driver_harness import status

STEP_S = 0.01
"""The world's and the servos' step, s."""


class ArmBench:
    """The emulated chain, the driver's process, and the test as the controller. A protocol's
    bench gives ``speed_address`` (where a Sync Write leaves each servo's speed) and, when
    its commands name their joints, ``joint_names``."""

    speed_address: int
    joint_names: tuple[str, ...] | None = None

    def __init__(self, system: System, arm: IntegratingJoints, servos: ServoChain) -> None:
        self.system, self.arm, self.servos = system, arm, servos
        self.joints = system.inbox(topics.ARM_JOINT_STATES)
        self.command = system.router.declare_publisher(
            topics.ARM_COMMAND.key(system.profile.namespace)
        )

    def serve(self) -> Iterator[Self]:
        """A fixture's body: the driver started and its first joint state in, this bench
        yielded; then the driver must still run and the chain have handled every packet."""
        self.system.start("arm_driver")
        self.joints.wait_for(lambda m: True, "a joint state")
        yield self
        assert self.system.processes[0].poll() is None, "the driver died"
        assert self.servos.counters["handler_errors"] == 0

    def send(self, velocities: Sequence[float]) -> None:
        header = Header(stamp_ns=time.time_ns(), frame="arm", seq=0, source="test")
        names = {} if self.joint_names is None else {"joint_names": self.joint_names}
        self.command.put(
            codec.encode(ArmCommand(header=header, joint_velocities=tuple(velocities), **names))
        )

    def run(self, seconds: float) -> None:
        """The world and the servos for ``seconds`` of their own time."""
        for _ in range(round(seconds / STEP_S)):
            self.servos.update(STEP_S)
            self.arm.step(STEP_S)

    def command_step(self, velocities: Sequence[float]) -> None:
        """Send ``velocities``, step the world and the servos 20 ms of their time, and let
        20 ms of the driver's pass."""
        self.send(velocities)
        self.run(0.02)
        time.sleep(0.02)

    def written(
        self,
        velocities: Sequence[float],
        wait_until: Callable[[Callable[[], bool], str], None] = _wait_until,
    ) -> None:
        """Send ``velocities`` until the driver has written a Sync Write for one of them."""
        before = self.servos.counters["sync_writes"]

        def sent() -> bool:
            self.send(velocities)
            time.sleep(0.005)
            return self.servos.counters["sync_writes"] > before

        wait_until(sent, f"a Sync Write for {velocities}")

    def speeds(self) -> list[int]:
        """Every servo's speed, as one Sync Write left them."""
        return self.servos.words(self.speed_address)

    def state(self) -> str:
        answer = status(self.system, "arm_driver")
        return "" if answer is None else answer.state
