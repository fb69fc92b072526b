"""The launcher's output: its own lines and its children's, prefixed with the time and a name."""

from __future__ import annotations

import threading
from datetime import datetime
from typing import IO


class Output:
    """Writes whole prefixed lines from many threads to two streams."""

    def __init__(self, out: IO[str], err: IO[str]) -> None:
        self.out = out
        self.err = err
        self._lock = threading.Lock()

    def line(self, stream: IO[str], prefix: str, text: str) -> None:
        """Write ``HH:MM:SS.mmm [prefix] text`` as one line (the local time) and flush it."""
        stamp = datetime.now().strftime("%H:%M:%S.%f")[:-3]
        with self._lock:
            stream.write(f"{stamp} [{prefix}] {text.rstrip()}\n")
            stream.flush()

    def say(self, text: str) -> None:
        """A line of the launcher's own, on the error stream."""
        self.line(self.err, "launch", text)

    def forward(self, pipe: IO[str], stream: IO[str], name: str) -> None:
        """Copy a child's pipe to ``stream`` line by line, prefixed with its name."""
        with pipe:
            for text in pipe:
                self.line(stream, name, text)
