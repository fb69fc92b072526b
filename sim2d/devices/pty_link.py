"""The device end of a pseudo-terminal: what an emulated serial device reads and writes.

A driver opens ``port`` (the slave, e.g. ``/dev/pts/3``) as it opens a real serial port; the
emulator reads and writes the master, never blocking. An optional symbolic link gives the port
a fixed name for a profile.
"""

from __future__ import annotations

import os
import select
import termios
import threading
import tty
from pathlib import Path
from typing import Self

READ_TIMEOUT_S = 0.02
"""How long a reader waits for bytes before it looks whether it should stop."""
_RATES = {
    getattr(termios, f"B{rate}"): rate
    for rate in (9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 576000, 921600)
    + (1000000, 2000000, 3000000)
    if hasattr(termios, f"B{rate}")
}
"""termios's speed constants by bit rate (those a Dynamixel or a Create runs at)."""


class PtyLink:
    """A raw pseudo-terminal, its master non-blocking, its slave at ``port`` (and ``link``)."""

    def __init__(self, link: Path | None = None) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        os.set_blocking(self.master, False)
        self.port = os.ttyname(self.slave)
        self.link = link
        if link is not None:
            if link.is_symlink() or link.exists():
                link.unlink()
            link.symlink_to(self.port)

    def baud(self) -> int | None:
        """The bit rate the driver set on the port (None: one not in ``_RATES``)."""
        return _RATES.get(termios.tcgetattr(self.master)[5])

    def close(self) -> None:
        """Close both ends; remove the link if it still names this port."""
        os.close(self.master)
        os.close(self.slave)
        if self.link is not None and self.link.is_symlink():
            if os.readlink(self.link) == self.port:
                self.link.unlink()


class SerialDevice:
    """An emulated device on a ``PtyLink``: a reader thread hands each chunk the driver wrote
    to ``receive``; ``send`` writes without blocking (when no driver reads, the pty's buffer
    fills and the rest is dropped and counted, as a device's bytes go nowhere unplugged).
    Subclasses add their threads to ``_threads`` and their counters to ``counters``."""

    name = "device"

    def __init__(self, link: Path | None, counters: tuple[str, ...]) -> None:
        self._pty = PtyLink(link)
        self.port = self._pty.port
        self.counters: dict[str, int] = dict.fromkeys((*counters, "bytes_dropped"), 0)
        self._lock = threading.Lock()
        self._stopping = threading.Event()
        self._closed = False
        reader = threading.Thread(target=self._read_loop, name=f"{self.name}-reader", daemon=True)
        self._threads = [reader]

    def __enter__(self) -> Self:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def start(self) -> None:
        for thread in self._threads:
            thread.start()

    def stop(self) -> None:
        """Stop the threads, close the pty and remove the link; safe to call twice."""
        if self._closed:
            return
        self._closed = True
        self._stopping.set()
        for thread in self._threads:
            if thread.is_alive():
                thread.join()
        self._pty.close()

    def receive(self, data: bytes) -> None:
        """Bytes the driver wrote (reader thread)."""
        raise NotImplementedError

    def send(self, data: bytes, counter: str | None = None) -> bool:
        """Write ``data`` to the driver; False when some of it was dropped. ``counter`` counts
        it as sent: before the write, so that a driver that has read it also sees it counted,
        and taken back when bytes were dropped."""
        if counter is not None:
            self.counters[counter] += 1
        try:
            written = os.write(self._pty.master, data)
        except BlockingIOError:
            written = 0
        self.counters["bytes_dropped"] += len(data) - written
        if counter is not None and written != len(data):
            self.counters[counter] -= 1
        return written == len(data)

    def _read_loop(self) -> None:
        while not self._stopping.is_set():
            readable, _, _ = select.select([self._pty.master], [], [], READ_TIMEOUT_S)
            if not readable:
                continue
            try:
                data = os.read(self._pty.master, 4096)
            except (BlockingIOError, InterruptedError):
                continue
            self.receive(data)
