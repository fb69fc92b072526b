"""The drivers' safety figures, on the emulated devices, through ``parsimony launch``.

Run as ``python -m studies.bench.driver_safety [--runs N] [--json]``. The bench plays the controller
(commands at 50 Hz) and hosts the emulated Create 2 and AX-18A chain, whose backends note when
they were told what (host monotonic time):

- ``stop_delay_ms``: from the last base command to the zero Drive Direct the driver sends by
  itself (``command_timeout_s`` 0.2 s in deploy/hardware.yaml);
- ``base_kill_to_stop_ms``: from ``kill -9`` of the base driver, the wheels driving, to the
  zero Drive Direct of the driver the launcher starts again (the Create never stops itself);
- ``arm_kill_to_still_ms``: from ``kill -9`` of the arm driver, the joints moving, to every
  servo at rest on its last goal, which needs no driver (each goal is at most ``lookahead_s``
  of motion ahead); ``arm_kill_to_back_ms``: to the restarted driver's first Sync Write;
- ``stray_header_gap_ms`` and ``garbage_gap_ms``: the gap in odometry around a stray
  ``19 255``, and around 32 random bytes, in the encoder stream (one frame every 15 ms);
  ``undisturbed_gap_ms`` the same with nothing injected.

Each kill comes after the driver has run longer than its profile's ``reset_after_s``, so every
one is a first restart, as after a real crash.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import yaml

from launch import query
from messages import codec, topics
from messages.commands import ArmCommand, BaseCommand
from messages.header import Header
from outputs.stdout import result_only_stdout, table
from profiles.deploy_files import DEPLOY
from profiles.endpoints import free_port
from profiles.profile import load_profile
from profiles.profile_files import read_profile_data
from protocols import create_oi
from sim2d.devices.ax_servos import AXChainEmulator
from sim2d.devices.create2 import Create2Emulator
from sim2d.devices.servo_chain import IntegratingJoints
from studies.bench.figures import run_bench, spread
from studies.launched import connect, launched

METRES_PER_COUNT = create_oi.mm_per_count(0.072) / 1000.0
RESET_AFTER_S = 1.0
STEP_S = 0.01


class Wheels:
    """The Create's world: wheel speeds told (with when), encoder counts that follow them."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.told: list[tuple[int, float, float]] = []
        self._speeds = (0.0, 0.0)
        self._counts = [0.0, 0.0]
        self._at = time.monotonic()

    def set_wheel_speeds(self, left: float, right: float) -> None:
        with self.lock:
            self._roll()
            self._speeds = (left, right)
            self.told.append((time.monotonic_ns(), left, right))

    def encoder_counts(self) -> tuple[int, int]:
        with self.lock:
            self._roll()
            return round(self._counts[0]), round(self._counts[1])

    def _roll(self) -> None:
        now = time.monotonic()
        for wheel in (0, 1):
            self._counts[wheel] += abs(self._speeds[wheel]) * (now - self._at) / METRES_PER_COUNT
        self._at = now

    def stopped_after(self, since_ns: int) -> int | None:
        """When the wheels were first told to stop after ``since_ns``."""
        with self.lock:
            return next(
                (t for t, left, right in self.told if t > since_ns and left == right == 0.0), None
            )


class Joints(IntegratingJoints):
    """The arm's world, stepped by the bench: when every joint last came to rest."""

    def __init__(self) -> None:
        super().__init__([0.0, -0.2, 0.2, 0.0, 0.5])
        self.still_since_ns: int | None = 0

    def set_joint_velocities(self, velocities: Sequence[float]) -> None:
        super().set_joint_velocities(velocities)
        still = not any(self.velocities)
        if still and self.still_since_ns is None:
            self.still_since_ns = time.monotonic_ns()
        elif not still:
            self.still_since_ns = None


class Controller:
    """Base and arm commands at 50 Hz on a thread of its own; either may be paused."""

    def __init__(self, session, namespace: str) -> None:
        self.base = session.declare_publisher(topics.BASE_COMMAND.key(namespace))
        self.arm = session.declare_publisher(topics.ARM_COMMAND.key(namespace))
        self.speed: float | None = None
        self.joints: tuple[float, ...] | None = None
        self.last_base_ns = 0
        self.running = True
        threading.Thread(target=self._loop, daemon=True).start()

    def _loop(self) -> None:
        while self.running:
            header = Header(stamp_ns=time.time_ns(), frame="", seq=0, source="bench")
            speed, joints = self.speed, self.joints
            if speed is not None:
                self.base.put(
                    codec.encode(
                        BaseCommand(
                            header=header,
                            forward_velocity=speed,
                            angular_velocity=0.0,
                            left_wheel=speed,
                            right_wheel=speed,
                        )
                    )
                )
                self.last_base_ns = time.monotonic_ns()
            if joints is not None:
                self.arm.put(codec.encode(ArmCommand(header=header, joint_velocities=joints)))
            time.sleep(0.02)


def wait(condition: Callable[[], object], what: str, timeout_s: float = 30.0) -> object:
    deadline = time.monotonic() + timeout_s
    while not (value := condition()):
        if time.monotonic() > deadline:
            raise RuntimeError(f"timed out waiting for {what}")
        time.sleep(0.001)
    return value


def profile_of(directory: Path, create: Path, servos: Path) -> Path:
    """deploy/hardware.yaml with its drivers alone, on the emulators' ports."""
    data = read_profile_data(DEPLOY / "hardware.yaml")
    data["namespace"] = "safety"
    data["zenoh"]["router"] = [f"tcp/127.0.0.1:{free_port()}"]
    ports = {"base_driver": create, "arm_driver": servos}
    for spec in data["components"]:
        spec["enabled"] = spec["name"] in ports
        if spec["enabled"]:
            spec["params"]["port"] = str(ports[spec["name"]])
            spec["restart"] = {"max_restarts": 1000, "reset_after_s": RESET_AFTER_S}
    path = directory / "safety.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


class Rig:
    """The emulators, the launched drivers and the bench's controller and odometry log; a
    context manager that stops them all."""

    def __init__(self, directory: Path) -> None:
        self.wheels, self.joints = Wheels(), Joints()
        self.stack = contextlib.ExitStack()
        self.create = self.stack.enter_context(Create2Emulator(self.wheels, directory / "create2"))
        self.servos = self.stack.enter_context(
            AXChainEmulator(self.joints, link=directory / "servos")
        )
        self.stepping = True
        threading.Thread(target=self._step_arm, daemon=True).start()
        self.stack.callback(setattr, self, "stepping", False)
        path = profile_of(directory, directory / "create2", directory / "servos")
        self.profile = load_profile(path)
        launcher = self.stack.enter_context(launched(path))
        self.session = self.stack.enter_context(connect(self.profile, launcher))
        self.odometry: list[int] = []
        self.session.declare_subscriber(
            topics.BASE_ODOMETRY.key(self.profile.namespace),
            lambda _: self.odometry.append(time.monotonic_ns()),
        )
        self.controller = Controller(self.session, self.profile.namespace)
        self.stack.callback(setattr, self.controller, "running", False)
        wait(lambda: {"base_driver", "arm_driver"} <= set(self.alive()), "both drivers alive")

    def __enter__(self) -> Rig:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.stack.close()

    def _step_arm(self) -> None:
        while self.stepping:
            self.servos.update(STEP_S)
            self.joints.step(STEP_S)
            time.sleep(STEP_S)

    def alive(self) -> list[str]:
        return query.live_components(self.session, self.profile.namespace, 0.5)

    def pid(self, name: str) -> int | None:
        answer = query.statuses(self.session, self.profile.namespace).get(name)
        return None if answer is None else answer.pid


def stop_delays(rig: Rig, runs: int) -> list[float]:
    delays = []
    for _ in range(runs):
        rig.controller.speed = 0.1
        wait(lambda: rig.wheels.told and rig.wheels.told[-1][1] == 0.1, "the wheels driving")
        time.sleep(0.2)
        rig.controller.speed = None
        time.sleep(0.03)  # the controller thread's last put
        last = rig.controller.last_base_ns
        stopped = wait(lambda t=last: rig.wheels.stopped_after(t), "the driver's stop")
        delays.append((stopped - last) / 1e6)
    return delays


def base_kills(rig: Rig, runs: int) -> list[float]:
    delays = []
    rig.controller.speed = 0.1
    for _ in range(runs):
        time.sleep(RESET_AFTER_S + 0.3)
        pid = wait(lambda: rig.pid("base_driver"), "the base driver's pid")
        killed = time.monotonic_ns()
        os.kill(pid, signal.SIGKILL)
        stopped = wait(lambda t=killed: rig.wheels.stopped_after(t), "the stop after the kill")
        delays.append((stopped - killed) / 1e6)
        wait(lambda old=pid: rig.pid("base_driver") not in (None, old), "the base driver back")
    rig.controller.speed = None
    return delays


def arm_kills(rig: Rig, runs: int) -> tuple[list[float], list[float]]:
    still, back = [], []
    for run in range(runs):
        direction = 1.0 if run % 2 == 0 else -1.0
        rig.controller.joints = (0.4 * direction, 0.0, 0.0, 0.0, 0.0)
        time.sleep(RESET_AFTER_S + 0.3)
        pid = wait(lambda: rig.pid("arm_driver"), "the arm driver's pid")
        writes = rig.servos.counters["sync_writes"]
        killed = time.monotonic_ns()
        os.kill(pid, signal.SIGKILL)
        rig.controller.joints = None  # the arm must come to rest with nobody driving it
        since = wait(lambda: rig.joints.still_since_ns, "the arm at rest")
        still.append(max(0, since - killed) / 1e6)
        rig.controller.joints = (0.0,) * 5
        wait(lambda n=writes: rig.servos.counters["sync_writes"] > n, "the restarted driver")
        back.append((time.monotonic_ns() - killed) / 1e6)
        rig.controller.joints = None
    return still, back


def odometry_gaps(rig: Rig, runs: int, garbage: Callable[[], bytes]) -> list[float]:
    rig.controller.speed = 0.05
    gaps = []
    for _ in range(runs):
        time.sleep(0.3)
        injected = time.monotonic_ns()
        rig.create.send(garbage())
        after = wait(
            lambda at=injected: next((t for t in rig.odometry if t > at), None),
            "odometry after the injection",
        )
        before = max(t for t in rig.odometry if t <= injected)
        gaps.append((after - before) / 1e6)
    rig.controller.speed = None
    return gaps


def measure(runs: int) -> dict:
    with (
        tempfile.TemporaryDirectory(prefix="parsimony-safety-") as directory,
        Rig(Path(directory)) as rig,
    ):
        delays = stop_delays(rig, runs)
        stray = odometry_gaps(rig, runs, lambda: bytes([create_oi.STREAM_HEADER, 255]))
        noise = odometry_gaps(rig, runs, lambda: os.urandom(32))
        normal = odometry_gaps(rig, runs, lambda: b"")
        kills = base_kills(rig, max(3, runs // 2))
        still, back = arm_kills(rig, max(3, runs // 2))
    return {
        "bench": "driver_safety",
        "stop_delay_ms": spread(delays),
        "base_kill_to_stop_ms": spread(kills),
        "arm_kill_to_still_ms": spread(still),
        "arm_kill_to_back_ms": spread(back),
        "stray_header_gap_ms": spread(stray),
        "garbage_gap_ms": spread(noise),
        "undisturbed_gap_ms": spread(normal),
        "stream_period_ms": create_oi.STREAM_PERIOD_S * 1e3,
    }


def lines(report: dict) -> list[str]:
    rows = [{"figure": name, **value} for name, value in report.items() if isinstance(value, dict)]
    return [table(rows)]


def main(argv: list[str] | None = None) -> int:
    return run_bench(__doc__, measure, lines, 20, argv)


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
