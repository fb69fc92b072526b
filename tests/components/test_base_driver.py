"""The base driver as a process against a pseudo-terminal, the test playing the Create byte for
byte: garbage, bad checksums, rollover storms, a stray header, lost frames, a port that vanishes
and returns, and a driver killed under its launcher."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import yaml

from launch import query
from messages import codec, topics
from messages.commands import BaseCommand
from messages.header import Header
from profiles.endpoints import free_port
from profiles.profile import load_profile
from profiles.profile_files import read_profile_data
from protocols import create_oi
from studies.launched import connect, launched
from tests.components.conftest import Inbox, System
from tests.components.driver_harness import DEPLOY, FakeLink, driver_system, frame, status

METRES_PER_COUNT = create_oi.mm_per_count(0.072) / 1000.0
STARTED = (
    bytes([create_oi.START, create_oi.SAFE])
    + create_oi.drive_direct(0, 0)
    + bytes([create_oi.STREAM, 2, create_oi.LEFT_ENCODER, create_oi.RIGHT_ENCODER])
)
"""What the driver writes first on opening the port: Start, Safe, the wheels stopped, the
stream of the encoders."""


class Create:
    """The test as the Create: what the driver wrote, and a controller's commands to it."""

    def __init__(self, link: FakeLink, session, namespace: str) -> None:
        self.link = link
        self.received = bytearray()
        self.command = session.declare_publisher(topics.BASE_COMMAND.key(namespace))

    def heard(self, expected: bytes) -> bool:
        self.received.extend(self.link.read())
        return expected in self.received

    def drive(self, speed: float = 0.1) -> bool:
        """Send one command, as a controller does at 50 Hz; whether the driver passed it on."""
        header = Header(stamp_ns=time.time_ns(), frame="base", seq=0, source="test")
        self.command.put(
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
        time.sleep(0.02)
        millimetres = round(speed * 1000)
        return self.heard(create_oi.drive_direct(millimetres, millimetres))


def started_driver(
    deployed, tmp_path: Path, wait_until, **params: object
) -> tuple[System, Create, Inbox]:
    """The driver on a fake Create, driving at 0.1 m/s, and its odometry: subscribed before the
    driver starts, so that its session knows the subscriber from its first frame on."""
    link = FakeLink(tmp_path / "create2")
    system = driver_system(deployed, tmp_path, "base_driver", link.link, **params)
    odometry = system.inbox(topics.BASE_ODOMETRY)
    system.start("base_driver")
    create = Create(link, system.router, system.profile.namespace)
    wait_until(lambda: create.heard(STARTED), "Start, Safe, stop and Stream")
    wait_until(create.drive, "Drive Direct 100 100 mm/s")
    return system, create, odometry


def test_the_base_driver_survives_bad_bytes_and_a_port_that_vanishes(
    deployed, tmp_path: Path, wait_until
) -> None:
    system, create, odometry = started_driver(deployed, tmp_path, wait_until)
    # Garbage, a bad checksum and a truncated frame, between good frames across the rollover,
    # 10 counts a frame (0.3 m/s).
    good = frame(65516, 0) + frame(65526, 0)
    broken = bytearray(frame(0, 0))
    broken[-1] ^= 0xFF
    create.link.write(good + os.urandom(50) + bytes(broken) + frame(10, 0)[:4])
    counts = iter(range(20, 3000, 10))

    def streamed() -> bool:
        """Keep driving and streaming, as the Create does every 15 ms."""
        create.link.write(frame(next(counts), 0))
        return create.drive() and any(20 <= m.left_encoder < 65000 for m in odometry.messages)

    wait_until(streamed, "odometry past the rollover")
    moved = odometry.messages[-1]
    # From 65516 through the rollover: every count forward, the bad frames skipped.
    travelled = (moved.left_encoder - 65516) & 0xFFFF
    assert abs(moved.left_distance - travelled * METRES_PER_COUNT) < 1e-9
    wait_until(
        lambda: (
            (status(system, "base_driver") or None) is not None
            and status(system, "base_driver").counters["bad_checksums"] >= 1
        ),
        "a counted bad checksum",
    )
    # No command for the timeout: the driver stops the wheels itself.
    wait_until(lambda: create.heard(create_oi.drive_direct(0, 0)), "the stop after the timeout")
    # The port vanishes and comes back: the driver opens it again and starts the OI again.
    create.link.close()
    wait_until(lambda: status(system, "base_driver").state == "no port", "the lost port seen")
    create.link = FakeLink(tmp_path / "create2")
    create.received.clear()
    wait_until(lambda: create.heard(STARTED), "the OI started again, wheels stopped")
    assert status(system, "base_driver").counters["reconnects"] >= 1
    assert system.processes[0].poll() is None
    create.link.close()


def test_a_rollover_storm_is_skipped_not_taken_for_motion(
    deployed, tmp_path: Path, wait_until
) -> None:
    """Counts that jump by 30,000 between frames with valid checksums would be 889 m/s."""
    system, create, odometry = started_driver(deployed, tmp_path, wait_until)
    storm = [1000, 31000, 1000, 31000, 1000, 1005, 1010]
    create.link.write(b"".join(frame(c, c) for c in storm))
    last = odometry.wait_for(lambda m: m.left_encoder == 1010, "the frame after the storm")
    for message in odometry.messages:
        assert abs(message.forward_velocity) <= 0.5 and abs(message.x) < 0.01, message
    assert abs(last.left_distance - 10 * METRES_PER_COUNT) < 1e-9  # 1000 -> 1005 -> 1010
    counters = status(system, "base_driver").counters
    assert counters["implausible_counts"] >= 4 and counters.get("errors.events", 0) == 0


def test_a_stray_header_costs_one_frame_not_a_quarter_second(
    deployed, tmp_path: Path, wait_until
) -> None:
    """``19 255`` announces 255 bytes; the driver knows its frames carry 6 and drops the 19 at
    once, so the very next frame is read (it used to wait for 258 bytes, 0.4 s of stream)."""
    system, create, odometry = started_driver(deployed, tmp_path, wait_until)
    create.link.write(frame(100, 100) + frame(104, 104))
    odometry.wait_for(lambda m: m.left_encoder == 104, "odometry before the stray header")
    create.link.write(bytes([create_oi.STREAM_HEADER, 255]) + frame(108, 108))
    odometry.wait_for(lambda m: m.left_encoder == 108, "the one frame after the stray header")


def test_a_frame_of_other_packets_is_counted_and_odometry_goes_on(
    deployed, tmp_path: Path, wait_until
) -> None:
    system, create, odometry = started_driver(deployed, tmp_path, wait_until)
    bumps = create_oi.stream_frame({create_oi.BUMPS_AND_WHEEL_DROPS: b"\x00"})
    cliff = create_oi.stream_frame(
        {create_oi.CLIFF_FRONT_LEFT_SIGNAL: b"\x00\x10", create_oi.LEFT_ENCODER: b"\x00\x02"}
    )  # 6 bytes too
    create.link.write(frame(0, 0) + bumps + cliff + frame(4, 4))
    odometry.wait_for(lambda m: m.left_encoder == 4, "odometry after the foreign frames")
    counters = status(system, "base_driver").counters
    assert counters["bad_frames"] >= 1 and counters.get("errors.events", 0) == 0


def test_speeds_after_lost_frames_are_taken_over_the_time_that_passed(
    deployed, tmp_path: Path, wait_until
) -> None:
    """At 0.2 m/s, 0.1 s of frames lost: the next frame's 45 counts are 0.1 s of motion (it
    used to be divided by one 15 ms period: 1.33 m/s). The command holds for the whole test."""
    system, create, odometry = started_driver(
        deployed, tmp_path, wait_until, command_timeout_s=10.0
    )
    wait_until(lambda: create.drive(0.2), "Drive Direct 200 200 mm/s")
    create.link.write(frame(500, 500) + frame(509, 509))
    odometry.wait_for(lambda m: m.left_encoder == 509, "odometry before the loss")
    time.sleep(0.1)  # the frames of 0.1 s lost on the line
    create.link.write(frame(554, 554))
    after = odometry.wait_for(lambda m: m.left_encoder == 554, "odometry after the loss")
    assert 0.0 < after.forward_velocity <= 0.25, after.forward_velocity


def dead(pid: int) -> bool:
    """Whether process ``pid`` has ended (a zombie not yet reaped has)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(") ", 1)[1].startswith("Z")
    except FileNotFoundError:
        return True


def test_a_killed_driver_comes_back_at_once_and_stops_the_wheels_first(
    tmp_path: Path, wait_until
) -> None:
    """The Create keeps its last Drive command for ever: after kill -9 of its driver, the
    launcher restarts it without a backoff and its first Drive Direct is a stop."""
    link = FakeLink(tmp_path / "create2")
    data = read_profile_data(DEPLOY / "hardware.yaml")
    for spec in data["components"]:
        spec["enabled"] = spec["name"] == "base_driver"
        if spec["name"] == "base_driver":
            spec["params"]["port"] = str(link.link)
    data["zenoh"]["router"] = [f"tcp/127.0.0.1:{free_port()}"]
    path = tmp_path / "base.yaml"
    path.write_text(yaml.safe_dump(data))
    profile = load_profile(path)
    with launched(path) as launcher:
        session = connect(profile, launcher)
        create = Create(link, session, profile.namespace)
        wait_until(lambda: create.heard(STARTED), "the driver's start")
        wait_until(create.drive, "Drive Direct 100 100 mm/s")
        pid = query.statuses(session, profile.namespace)["base_driver"].pid
        os.kill(pid, signal.SIGKILL)
        wait_until(lambda: dead(pid), "the killed driver gone")
        while create.link.read():  # what the killed driver wrote: its restart takes far longer
            pass
        create.received.clear()
        wait_until(lambda: create.heard(STARTED), "the restarted driver's start", timeout_s=30.0)
        first_move = create.received.find(create_oi.drive_direct(100, 100))
        assert first_move == -1 or first_move > create.received.index(STARTED)
        wait_until(create.drive, "the restarted driver driving again")
        assert query.statuses(session, profile.namespace)["base_driver"].pid != pid
        session.close()
    link.close()
