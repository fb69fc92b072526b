"""Single key presses from a terminal, read without Enter and without blocking.

``terminal_keys()`` puts standard input in cbreak mode (no line editing, no echo; Ctrl-C
still interrupts) for the duration of a ``with`` block and yields a ``KeyReader``; the
terminal's settings come back on every way out of the block: its end or an exception (Ctrl-C,
and SIGTERM where the command raises one for it: ``parsimony.stop_signals``). When standard
input is not a terminal it yields ``None`` and changes nothing.
"""

from __future__ import annotations

import os
import re
import select
import sys
import termios
import tty
from collections import deque
from collections.abc import Iterator
from contextlib import contextmanager

RIGHT = "right"
"""The key the right arrow gives."""
QUIT = "q"
"""The quit key; also what is read once the terminal has gone (end of input)."""
ESCAPES = {"\x1b[C": RIGHT, "\x1bOC": RIGHT}
"""Escape sequences read as one key: the right arrow (normal and application cursor mode)."""
ESCAPE_SEQUENCE = re.compile(r"\x1b(?:[\[O][0-9;]*.?)?", re.DOTALL)
"""An escape sequence: ESC, then optionally ``[`` or ``O``, parameters and a final character."""


class KeyReader:
    """The keys pressed on the terminal ``fd``, one at a time, in the order typed."""

    def __init__(self, fd: int) -> None:
        self._fd = fd
        self._pending: deque[str] = deque()

    def read(self, timeout_s: float | None) -> str | None:
        """The next key, waiting at most ``timeout_s`` s (``None``: until one comes); ``None``
        when none came. Escape sequences other than ``ESCAPES`` are dropped."""
        if not self._pending:
            ready, _, _ = select.select([self._fd], [], [], timeout_s)
            if not ready:
                return None
            try:
                data = os.read(self._fd, 64)
            except OSError:  # the terminal hung up (EIO)
                data = b""
            self._pending.extend(split_keys(data.decode(errors="replace")) if data else [QUIT])
        return self._pending.popleft() if self._pending else None


def split_keys(text: str) -> list[str]:
    """The keys in what one read gave: characters, and ``ESCAPES`` by their names (other
    escape sequences, such as the other arrows, are dropped)."""
    keys = []
    while text:
        sequence = ESCAPE_SEQUENCE.match(text)
        if sequence is None:
            keys.append(text[0])
            text = text[1:]
            continue
        if sequence.group() in ESCAPES:
            keys.append(ESCAPES[sequence.group()])
        text = text[sequence.end() :]
    return keys


@contextmanager
def terminal_keys() -> Iterator[KeyReader | None]:
    """Standard input in cbreak mode and a ``KeyReader`` of it, or ``None`` if it is no
    terminal."""
    if sys.stdin is None or not sys.stdin.isatty():
        yield None
        return
    fd = sys.stdin.fileno()
    saved = termios.tcgetattr(fd)
    try:
        tty.setcbreak(fd, termios.TCSANOW)
        yield KeyReader(fd)
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)
