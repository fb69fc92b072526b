"""The README's first hour, run exactly as written: a launch with its recording, two goals, the
recording described, reported and replayed."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

from deploy import DEPLOY

ROOT = DEPLOY.parent
SAFETY_NET_S = 900
"""Only against a hang: each command of the block waits on its own events."""


def first_hour_block() -> str:
    """The shell block under the README's '## Your first hour'."""
    section = (ROOT / "README.md").read_text().split("## Your first hour", 1)[1]
    match = re.search(r"```sh\n(.*?)```", section, re.DOTALL)
    assert match, "the first hour has no sh block"
    return match.group(1)


def test_the_first_hour_of_the_readme_runs_as_written(tmp_path: Path) -> None:
    """In a folder of its own (``deploy`` and ``.venv`` as the root has them), ``bash -e``: every
    command exits 0, the goals are reached, the recording is whole and holds them, the report
    is written and the replay ends."""
    for name in ("deploy", ".venv"):
        (tmp_path / name).symlink_to(ROOT / name)
    result = subprocess.run(
        ["bash", "-e", "-c", first_hour_block()],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=SAFETY_NET_S,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    assert result.stdout.count("reached in") == 2, result.stdout
    assert "supervisor reached" in result.stderr
    # info's table: the two goals on goal/request, recorded
    assert re.search(r"^sim/goal/request\s+Goal\s+\d+\s+2\s", result.stdout, re.M), result.stdout
    assert (tmp_path / "first_report" / "judged.json").is_file()
    assert (tmp_path / "first_report" / "base_path.png").is_file()
    assert "Traceback" not in result.stderr
