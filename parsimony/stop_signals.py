"""How a command that runs until it is stopped takes SIGINT and SIGTERM (`parsimony view`,
`parsimony replay`).

Each stop signal gets a handler of its own, whatever the process inherited: a command started
as a shell's background job (``cmd &`` without job control, ``nohup``, a test suite run so)
inherits SIGINT ignored, and Python then leaves it ignored, so that Ctrl-C or ``kill -INT``
would do nothing. The first stop signal is noted (``Stop.signal``) and, if asked, raised in the
main thread as ``Interrupted``; those that follow are ignored, so that the command's cleanup
(its Zenoh session closed, its server stopped) runs to its end. The previous handlers come back
when the block ends.
"""

from __future__ import annotations

import signal
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
POLL_S = 0.1
"""How often ``Stop.wait`` looks whether a stop signal came (a signal that comes while the
main thread waits in a system call is handled when it returns; a ``signal.pause`` would wait
for one more)."""


class Interrupted(KeyboardInterrupt):
    """A stop signal, raised in the main thread; ``signal`` names it."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.signal = name

    @property
    def exit_code(self) -> int:
        """128 plus the signal's number, as a shell reports a command a signal ended."""
        return 128 + signal.Signals[self.signal].value


class Stop:
    """Which stop signal came first (``signal``, its name; None while none has)."""

    def __init__(self) -> None:
        self.signal: str | None = None

    def wait(self) -> str:
        """Until a stop signal comes; its name."""
        while self.signal is None:
            time.sleep(POLL_S)
        return self.signal


@contextmanager
def stop_signals(
    signals: Sequence[signal.Signals] = STOP_SIGNALS, raising: bool = False
) -> Iterator[Stop]:
    """Inside the block, the first of ``signals`` is noted in the ``Stop`` yielded (and raised
    as ``Interrupted`` if ``raising``), the others ignored. From the main thread only."""
    stop = Stop()

    def on_signal(signum: int, _frame: object) -> None:
        if stop.signal is not None:
            return
        stop.signal = signal.Signals(signum).name
        if raising:
            raise Interrupted(stop.signal)

    previous = {s: signal.signal(s, on_signal) for s in signals}
    try:
        yield stop
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
