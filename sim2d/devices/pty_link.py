"""The device end of a pseudo-terminal: what an emulated serial device reads and writes.

A driver opens ``port`` (the slave, e.g. ``/dev/pts/3``) as it opens a real serial port; the
emulator reads and writes the master, never blocking. An optional symbolic link gives the port
a fixed name for a profile.
"""

from __future__ import annotations

import os
import tty
from pathlib import Path


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

    def close(self) -> None:
        """Close both ends; remove the link if it still names this port."""
        os.close(self.master)
        os.close(self.slave)
        if self.link is not None and self.link.is_symlink():
            if os.readlink(self.link) == self.port:
                self.link.unlink()
