"""For tests: the `parsimony` command run as a process, and whether a process is gone."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def parsimony(*arguments: str) -> subprocess.CompletedProcess:
    """``parsimony ARGUMENTS`` as a new user runs it, its output captured as text."""
    return subprocess.run(
        [sys.executable, "-m", "parsimony.cli", *arguments], capture_output=True, text=True
    )


def process_gone(pid: int) -> bool:
    """Whether ``pid`` has exited (a zombie counts as exited)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return True
    return state == "Z"
