"""`parsimony ARGS` run as a process of its own, as a user runs it (for what only a real process
shows: its whole stdout, its exit, what a library writes to its file descriptors)."""

from __future__ import annotations

import subprocess
import sys


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "parsimony.cli", *args],
        capture_output=True,
        text=True,
        timeout=300,
    )
