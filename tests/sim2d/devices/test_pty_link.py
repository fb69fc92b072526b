"""The device end of a pseudo-terminal (sim2d/devices/pty_link.py): a driver opens the port (or
its link) as a serial port, its bytes reach the device, the device's reach it, and what no
driver reads is dropped and counted, never blocking."""

from __future__ import annotations

import os
import select
import threading
from pathlib import Path

from sim2d.devices.pty_link import SerialDevice

DEADLINE_S = 30.0
"""A safety net only: each wait ends as soon as the bytes are there."""


class Echo(SerialDevice):
    """A device that answers each chunk with the same bytes."""

    name = "echo"

    def __init__(self, link: Path | None) -> None:
        super().__init__(link, ("replies",))
        self.heard = threading.Event()

    def receive(self, data: bytes) -> None:
        self.send(data, "replies")
        self.heard.set()


def read_exactly(fd: int, size: int) -> bytes:
    data = b""
    while len(data) < size:
        readable, _, _ = select.select([fd], [], [], DEADLINE_S)
        assert readable, f"no reply within {DEADLINE_S} s, got {data!r}"
        data += os.read(fd, size - len(data))
    return data


def test_a_driver_on_the_link_talks_to_the_device_and_the_link_goes_with_it(
    tmp_path: Path,
) -> None:
    link = tmp_path / "ttyECHO"
    with Echo(link) as device:
        assert os.path.realpath(link) == device.port
        driver = os.open(link, os.O_RDWR | os.O_NOCTTY)
        try:
            os.write(driver, b"\x80\x83")
            assert read_exactly(driver, 2) == b"\x80\x83"
        finally:
            os.close(driver)
        assert device.counters["replies"] >= 1 and device.counters["bytes_dropped"] == 0
    assert not link.exists() and not link.is_symlink()


def test_what_no_driver_reads_is_dropped_and_counted_without_blocking() -> None:
    device = Echo(None)  # not started: nobody reads either end
    try:
        sent = [device.send(bytes(1024), "replies") for _ in range(1024)]  # 1 MiB
        assert sent[0] and not sent[-1]
        assert device.counters["replies"] == sent.count(True)
        assert device.counters["bytes_dropped"] > 0
    finally:
        device.stop()
