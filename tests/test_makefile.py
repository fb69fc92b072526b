"""The Makefile's long steps say what they do before they start (make -n: nothing is run)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LONG_STEPS = ("pip install", "npm ci", "parsimony experiment")
"""Commands that run for more than a second: pip with --quiet, npm, the experiment."""


@pytest.mark.skipif(shutil.which("make") is None, reason="needs make")
def test_each_long_step_of_make_demo_and_test_is_announced_first() -> None:
    """Before, `make demo`'s first run built the environment for about 70 s with pip --quiet
    and not a word."""
    # -W: as if the lock and the client's package.json had just changed, so both are rebuilt.
    done = subprocess.run(
        [
            "make",
            "-n",
            "-W",
            "requirements.lock",
            "-W",
            "tests/foxglove_client/package.json",
            "demo",
            "foxglove-client",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    commands = [line for line in done.stdout.splitlines() if not line.startswith("\t")]
    long = [i for i, line in enumerate(commands) if any(step in line for step in LONG_STEPS)]
    assert len(long) == 4, commands  # two pip installs, the experiment, npm ci
    for index in long:
        assert commands[index - 1].startswith('echo "[make] '), commands[index - 1 : index + 1]
    said = done.stdout
    assert "packages pinned in" in said and "about a minute" in said
