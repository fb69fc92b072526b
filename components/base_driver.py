"""The base driver: an iRobot Create 2 over its Open Interface on a serial port.

At start, and each time the port comes back: Start, then Safe or Full (``mode``), a Drive
Direct of 0 (a driver that comes back after a crash stops the wheels before anything else),
and a Stream of the wheel encoders (packets 43 and 44) every 15 ms. Each ``base/command``
becomes a Drive Direct of its wheel speeds (mm/s, right wheel first, clamped to the robot's
wheel speed limit; a non-finite one stops the wheels). The Create keeps its last Drive command
for ever, so the driver stops the wheels ``command_timeout_s`` after the last command (an
alarm re-armed by each command, not a polling timer), on exit and on SIGTERM.

Each stream frame (checksum verified, and carrying exactly the packets asked for, so that a
stray header byte is dropped at once) yields a ``base/odometry``: the counts' change, rollover
handled, signed by the commanded direction of each wheel (the encoders are not quadrature),
the wheel distances and the pose dead-reckoned from them, as the simulator publishes it. The
time a frame covers is a whole number of stream periods, counted on the host's clock and at
least one per frame refused before it, so that the speeds stay right when frames were lost. A
change larger than the wheel speed limit allows
in that time (a corrupt count with a valid checksum) is counted (``implausible_counts``) and
skipped, the counts taken as the new reference. A broken frame or a bad checksum is counted and
skipped; a vanished port is counted, logged and opened again every ``reconnect_s`` until it
returns. The driver never dies on bad bytes.
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
from components.stop_latch import StopLatch
from messages import topics
from messages.commands import BaseCommand
from messages.odometry import BaseOdometry
from messages.stop import StopState
from protocols import create_oi
from wbc.base_motion import dead_reckoning
from wbc.robot import MobileManipulator

WATCH_PERIOD_S = 0.05
"""How often the driver looks whether a lost port is back."""

ENCODERS = (create_oi.LEFT_ENCODER, create_oi.RIGHT_ENCODER)

PLAUSIBLE_SPEED_FACTOR = 1.5
"""A wheel's count may change by up to this many times its speed limit over the frame's time,
plus ``PLAUSIBLE_SLACK_COUNTS``, before the change is taken for a corrupt count."""
PLAUSIBLE_SLACK_COUNTS = 2


class BaseDriver(Component):
    """base/command in, base/odometry out, over the Create's serial port."""

    reads = (Input(topics.BASE_COMMAND),)
    writes = (topics.BASE_ODOMETRY,)
    params = (
        Param("port", str, "/dev/ttyUSB0", doc="serial port of the Create"),
        Param("mode", str, "safe", choices=("safe", "full"), doc="OI mode after Start"),
        Param(
            "command_timeout_s",
            float,
            0.2,
            low=0.01,
            high=10.0,
            doc="stop the wheels after this long without a command, s",
        ),
        Param("reconnect_s", float, 0.5, low=0.05, high=60.0, doc="retry period of a lost port"),
    )

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        if node.profile.robot is None:
            raise ParamError("the base driver needs the profile's `robot`")
        self.base = MobileManipulator.from_yaml(node.profile.robot).base
        self.metres_per_count = create_oi.mm_per_count(2.0 * self.base.wheel_radius) / 1000.0
        self.output = node.publisher(topics.BASE_ODOMETRY)
        for name in (
            "frames",
            "bad_checksums",
            "bad_frames",
            "resync_bytes",
            "port_errors",
            "reconnects",
            "stops",
            "implausible_counts",
            "non_finite_commands",
        ):
            node.counters[name] = 0
        self.serial: serial.Serial | None = None
        self.parser = create_oi.StreamParser(ENCODERS)
        self.counts: tuple[int, int] | None = None
        self.frame_ns = 0
        """Host time of the last frame, for the time the next one covers."""
        self.distances = [0.0, 0.0]
        self.pose = (0.0, 0.0, 0.0)
        self.commanded = (0.0, 0.0)  # left, right, m/s: the sign of each wheel's motion
        self.moving = False
        self.lock = threading.Lock()  # the serial port, shared with the reader thread
        self.closing = threading.Event()
        self._tried_ns = 0
        self._open()  # a port that is not there yet is opened by the watch timer when it is
        self.timeout = node.alarm(self.on_timeout)
        self.latch = StopLatch(node, self.on_stop)
        node.subscribe(topics.BASE_COMMAND, self.on_command)
        node.timer(WATCH_PERIOD_S, self.watch)
        self.reader = threading.Thread(target=self._read, name="create-reader", daemon=True)
        self.reader.start()

    # -- the port ---------------------------------------------------------------------------

    def _open(self) -> None:
        """Open the port and start the OI: Start, the mode, wheels stopped, the encoder stream."""
        self.node.state = "no port"
        try:
            port = serial.Serial(self.node.params["port"], create_oi.BAUD, timeout=0.05)
            mode = create_oi.FULL if self.node.params["mode"] == "full" else create_oi.SAFE
            port.write(
                bytes([create_oi.START, mode])
                + create_oi.drive_direct(0, 0)
                + create_oi.stream_request(ENCODERS)
            )
        except (serial.SerialException, OSError) as error:
            self.node.warn("port_errors", f"cannot open {self.node.params['port']}: {error}")
            return
        with self.lock:
            self.serial = port
        self.commanded, self.moving = (0.0, 0.0), False
        self.node.state = "running"
        self.counts = None  # the first frame after a reconnect only sets the reference

    def _lost(self, error: Exception) -> None:
        """Close a port that failed (either thread); the watch timer opens it again."""
        with self.lock:
            port, self.serial = self.serial, None
            if port is not None:
                try:
                    port.close()
                except (serial.SerialException, OSError):
                    pass
        if port is not None:
            self.node.post(lambda: self._say_lost(error))

    def _say_lost(self, error: Exception) -> None:
        self.node.count("port_errors")
        self.node.warn("port_errors", f"lost {self.node.params['port']}: {error}")

    def _write(self, data: bytes) -> bool:
        """Write under the lock, so that the reader thread never closes the port meanwhile."""
        with self.lock:
            port = self.serial
            if port is None:
                return False
            try:
                port.write(data)
                return True
            except (serial.SerialException, OSError, TypeError) as error:
                failed = error
        self._lost(failed)
        return False

    def _read(self) -> None:
        """Reader thread: bytes in as they come (a fixed-size read would wait for its timeout,
        holding frames up to 50 ms), frames parsed, each posted to the handler thread with the
        host time it was complete."""
        while not self.closing.is_set():
            with self.lock:
                port = self.serial
            if port is None:
                time.sleep(0.01)  # the watch timer reopens it
                continue
            try:
                data = port.read(max(1, port.in_waiting))  # what is there, at least one byte
            except (serial.SerialException, OSError, TypeError) as error:
                self._lost(error)
                continue
            if data:
                now = time.monotonic_ns()
                for frame in self.parser.feed(data):
                    self.node.post(lambda f=frame, t=now: self.on_frame(f, t))

    # -- handlers ---------------------------------------------------------------------------

    def on_command(self, command: BaseCommand) -> None:
        """Drive Direct with the command's wheel speeds, clamped to the limit (a non-finite
        one stops the wheels); the stop alarm set ``command_timeout_s`` ahead."""
        left, right = command.left_wheel, command.right_wheel
        if not (math.isfinite(left) and math.isfinite(right)):
            self.node.count("non_finite_commands")
            self.node.warn("non_finite_commands", f"non-finite wheel speeds {left}, {right}")
            self.stop_wheels()
            return
        if self.latch.refuses():
            return  # the wheels were stopped when the stop came
        limit = self.base.wheel_speed_max
        left, right = max(-limit, min(limit, left)), max(-limit, min(limit, right))
        self.commanded = (left, right)
        self.moving = left != 0.0 or right != 0.0
        self._write(create_oi.drive_direct(round(right * 1000), round(left * 1000)))
        self.timeout.set(self.node.params["command_timeout_s"])

    def on_stop(self, state: StopState) -> None:
        """The emergency stop (``components.stop_latch``): the wheels stopped at once."""
        if state.stopped:
            self.timeout.cancel()
            self.stop_wheels()

    def on_timeout(self) -> None:
        """Alarm: no command for ``command_timeout_s``."""
        if self.moving:
            self.stop_wheels()

    def watch(self) -> None:
        """Timer: reopen a lost port, and stop the wheels as soon as it is back."""
        with self.lock:
            lost = self.serial is None
        now = time.monotonic_ns()
        if lost and now - self._tried_ns > self.node.params["reconnect_s"] * 1e9:
            self._tried_ns = now
            self._open()
            if self.serial is not None:
                self.node.count("reconnects")

    def stop_wheels(self) -> None:
        self.commanded, self.moving = (0.0, 0.0), False
        self.node.count("stops")
        self._write(create_oi.drive_direct(0, 0))

    def on_frame(self, frame: create_oi.StreamFrame, received_ns: int) -> None:
        """One stream frame: the encoder counts' change, signed by the commanded direction,
        over the whole stream periods since the last frame (one per frame lost at least)."""
        self.node.counters["frames"] += 1
        self.node.counters["bad_checksums"] = self.parser.bad_checksums
        self.node.counters["bad_frames"] = self.parser.bad_frames
        self.node.counters["resync_bytes"] = self.parser.resyncs
        counts = (frame.packets[create_oi.LEFT_ENCODER], frame.packets[create_oi.RIGHT_ENCODER])
        elapsed = round((received_ns - self.frame_ns) / 1e9 / create_oi.STREAM_PERIOD_S)
        periods = max(1 + frame.lost, elapsed)
        self.frame_ns = received_ns
        previous, self.counts = self.counts, counts
        if previous is None:
            return
        deltas = [
            abs(create_oi.encoder_delta(new, old))
            for new, old in zip(counts, previous, strict=True)
        ]
        if max(deltas) > self.plausible_counts(periods):
            self.node.count("implausible_counts")
            self.node.warn(
                "implausible_counts",
                f"encoder counts jumped by {max(deltas)} in "
                f"{periods} stream period(s); frame skipped",
            )
            return
        signed = [
            math.copysign(d * self.metres_per_count, v) if v != 0.0 else 0.0
            for d, v in zip(deltas, self.commanded, strict=True)
        ]
        self.distances = [a + b for a, b in zip(self.distances, signed, strict=True)]
        self.pose = dead_reckoning(*self.pose, signed[0], signed[1], self.base.wheel_base)
        covered_s = periods * create_oi.STREAM_PERIOD_S
        left, right = signed[0] / covered_s, signed[1] / covered_s
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

    def plausible_counts(self, periods: int) -> int:
        """The largest count change a wheel can make in ``periods`` stream periods."""
        metres = self.base.wheel_speed_max * periods * create_oi.STREAM_PERIOD_S
        return math.ceil(
            PLAUSIBLE_SPEED_FACTOR * metres / self.metres_per_count + PLAUSIBLE_SLACK_COUNTS
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
