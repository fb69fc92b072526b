"""launch.stop's wait for a stopping process, on real processes."""

from __future__ import annotations

import signal
import subprocess

import pytest

from launch.stop import wait_ended


def test_a_wait_ends_with_the_process_or_times_out_while_it_runs() -> None:
    """A process that runs on is waited for until the timeout; once ended by a signal, its exit
    code comes back, and again when it has been reaped already."""
    process = subprocess.Popen(["sleep", "60"])
    try:
        with pytest.raises(subprocess.TimeoutExpired):
            wait_ended(process, 0.05)
        process.send_signal(signal.SIGTERM)
        assert wait_ended(process, 30.0) == -signal.SIGTERM
        assert wait_ended(process, 30.0) == -signal.SIGTERM
    finally:
        process.kill()
        process.wait()
