"""The base driver: an iRobot Create 2 over its Open Interface on a serial port.

At start, and each time the port comes back: Start, then Safe or Full (``mode``), and a
Stream of the wheel encoders (packets 43 and 44) every 15 ms. Each ``base/command`` becomes a
Drive Direct of its wheel speeds (mm/s, right wheel first, clamped to the robot's wheel speed
limit). The Create keeps its last Drive command for ever, so the driver stops the wheels when
no command has come for ``command_timeout_s``, on exit and on SIGTERM.

Each stream frame (checksum verified) yields a ``base/odometry``: the counts' change, rollover
handled, signed by the commanded direction of each wheel (the encoders are not quadrature),
the wheel distances and the pose dead-reckoned from them, as the simulator publishes it. A
broken frame or a bad checksum is counted and skipped; a vanished port is counted, logged and
opened again every ``reconnect_s`` until it returns. The driver never dies on bad bytes.
"""

from __future__ import annotations

import math
import threading
import time

import serial

from components.params import Param, ParamError
from components.process_entry import run_component
from components.pubsub import Input
from components.runtime import Component, Node
from messages import topics
from messages.commands import BaseCommand
from messages.odometry import BaseOdometry
from protocols import create_oi
from wbc.base_motion import dead_reckoning
from wbc.robot import MobileManipulator

WATCH_PERIOD_S = 0.05
"""How often the driver checks the command timeout and the port."""


class BaseDriver(Component):
    """base/command in, base/odometry out, over the Create's serial port."""

    reads = (Input(topics.BASE_COMMAND),)
    writes = (topics.BASE_ODOMETRY,)
    params = (
        Param("port", str, "/dev/ttyUSB0", doc="serial port of the Create"),
        Param("mode", str, "safe", choices=("safe", "full"), doc="OI mode after Start"),
        Param("command_timeout_s", float, 0.2, low=0.01, high=10.0,
              doc="stop the wheels after this long without a command, s"),
        Param("reconnect_s", float, 0.5, low=0.05, high=60.0, doc="retry period of a lost port"),
    )  # fmt: skip

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        if node.profile.robot is None:
            raise ParamError("the base driver needs the profile's `robot`")
        self.base = MobileManipulator.from_yaml(node.profile.robot).base
        self.metres_per_count = create_oi.mm_per_count(2.0 * self.base.wheel_radius) / 1000.0
        self.output = node.publisher(topics.BASE_ODOMETRY)
        for name in ("frames", "bad_checksums", "resync_bytes", "port_errors", "reconnects",
                     "stops"):  # fmt: skip
            node.counters[name] = 0
        self.serial: serial.Serial | None = None
        self.parser = create_oi.StreamParser()
        self.counts: tuple[int, int] | None = None
        self.distances = [0.0, 0.0]
        self.pose = (0.0, 0.0, 0.0)
        self.commanded = (0.0, 0.0)  # left, right, m/s: the sign of each wheel's motion
        self.last_command_ns: int | None = None
        self.moving = False
        self.lock = threading.Lock()  # the serial port, shared by the reader thread
        self.closing = threading.Event()
        self._tried_ns = 0
        self._open()  # a port that is not there yet is opened by the watch timer when it is
        node.subscribe(topics.BASE_COMMAND, self.on_command)
        node.timer(WATCH_PERIOD_S, self.watch)
        self.reader = threading.Thread(target=self._read, name="create-reader", daemon=True)
        self.reader.start()

    # -- the port ---------------------------------------------------------------------------

    def _open(self) -> None:
        """Open the port and start the OI: Start, the mode, the encoder stream."""
        self.node.state = "no port"
        try:
            port = serial.Serial(self.node.params["port"], create_oi.BAUD, timeout=0.05)
            mode = create_oi.FULL if self.node.params["mode"] == "full" else create_oi.SAFE
            port.write(bytes([create_oi.START, mode]))
            port.write(create_oi.stream_request([create_oi.LEFT_ENCODER,
                                                 create_oi.RIGHT_ENCODER]))  # fmt: skip
        except (serial.SerialException, OSError) as error:
            self.node.warn("port_errors", f"cannot open {self.node.params['port']}: {error}")
            return
        with self.lock:
            self.serial = port
        self.node.state = "running"
        self.counts = None  # the first frame after a reconnect only sets the reference

    def _lost(self, error: Exception) -> None:
        with self.lock:
            port, self.serial = self.serial, None
        if port is not None:
            self.node.post(lambda: self._say_lost(error))
            try:
                port.close()
            except (serial.SerialException, OSError):
                pass

    def _say_lost(self, error: Exception) -> None:
        self.node.count("port_errors")
        self.node.warn("port_errors", f"lost {self.node.params['port']}: {error}")

    def _write(self, data: bytes) -> bool:
        with self.lock:
            port = self.serial
        if port is None:
            return False
        try:
            port.write(data)
            return True
        except (serial.SerialException, OSError) as error:
            self._lost(error)
            return False

    def _read(self) -> None:
        """Reader thread: bytes in, frames parsed, each posted to the handler thread."""
        while not self.closing.is_set():
            with self.lock:
                port = self.serial
            if port is None:
                time.sleep(0.01)  # the watch timer reopens it
                continue
            try:
                data = port.read(64)
            except (serial.SerialException, OSError, TypeError) as error:
                self._lost(error)
                continue
            if data:
                for frame in self.parser.feed(data):
                    self.node.post(lambda f=frame: self.on_frame(f))

    # -- handlers ---------------------------------------------------------------------------

    def on_command(self, command: BaseCommand) -> None:
        """Drive Direct with the command's wheel speeds, clamped to the limit."""
        limit = self.base.wheel_speed_max
        left = max(-limit, min(limit, command.left_wheel))
        right = max(-limit, min(limit, command.right_wheel))
        if not (math.isfinite(left) and math.isfinite(right)):
            raise ValueError(f"non-finite wheel speeds {left}, {right}")
        self.commanded = (left, right)
        self.last_command_ns = self.node.clock.monotonic_ns()
        self.moving = left != 0.0 or right != 0.0
        self._write(create_oi.drive_direct(round(right * 1000), round(left * 1000)))

    def watch(self) -> None:
        """Timer: stop the wheels after the command timeout; reopen a lost port."""
        timeout_ns = self.node.params["command_timeout_s"] * 1e9
        now = self.node.clock.monotonic_ns()
        stale = self.last_command_ns is None or now - self.last_command_ns > timeout_ns
        if stale and self.moving:
            self.stop_wheels()
        with self.lock:
            lost = self.serial is None
        if lost and now - self._tried_ns > self.node.params["reconnect_s"] * 1e9:
            self._tried_ns = now
            self._open()
            if self.serial is not None:
                self.node.count("reconnects")
                self.stop_wheels()

    def stop_wheels(self) -> None:
        self.commanded, self.moving = (0.0, 0.0), False
        self.node.count("stops")
        self._write(create_oi.drive_direct(0, 0))

    def on_frame(self, packets: dict[int, int]) -> None:
        """One stream frame: the encoder counts' change, signed by the commanded direction."""
        self.node.counters["frames"] += 1
        self.node.counters["bad_checksums"] = self.parser.bad_checksums
        self.node.counters["resync_bytes"] = self.parser.resyncs
        counts = (packets[create_oi.LEFT_ENCODER], packets[create_oi.RIGHT_ENCODER])
        if self.counts is None:
            self.counts = counts
            return
        deltas = [abs(create_oi.encoder_delta(new, old)) * self.metres_per_count
                  for new, old in zip(counts, self.counts, strict=True)]  # fmt: skip
        self.counts = counts
        signed = [math.copysign(d, v) if v != 0.0 else 0.0
                  for d, v in zip(deltas, self.commanded, strict=True)]  # fmt: skip
        self.distances = [a + b for a, b in zip(self.distances, signed, strict=True)]
        self.pose = dead_reckoning(*self.pose, signed[0], signed[1], self.base.wheel_base)
        period = create_oi.STREAM_PERIOD_S
        left, right = signed[0] / period, signed[1] / period
        x, y, phi = self.pose
        self.output.put(
            BaseOdometry(
                header=self.node.header("odom", None, self.output.next_seq),
                left_encoder=counts[0],
                right_encoder=counts[1],
                left_distance=self.distances[0],
                right_distance=self.distances[1],
                x=x,
                y=y,
                phi=phi,
                forward_velocity=0.5 * (left + right),
                angular_velocity=(right - left) / self.base.wheel_base,
            )
        )

    def shutdown(self) -> None:
        """Stop the wheels, stop the stream, close the port."""
        self.stop_wheels()
        self._write(create_oi.pause_resume(False))
        self.closing.set()
        with self.lock:
            port, self.serial = self.serial, None
        if port is not None:
            port.close()


if __name__ == "__main__":
    run_component(BaseDriver)
