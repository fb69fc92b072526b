"""The README's first hour, run exactly as written: a launch with its recording, watched, two
goals, the live view, the recording described, reported, re-run with another law, compared,
replayed at another rate into a Foxglove view, the view's layout written, and the emulated
hardware launched."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import pytest

from profiles.deploy_files import DEPLOY

ROOT = DEPLOY.parent
SAFETY_NET_S = 900
"""Only against a hang: each command of the block waits on its own events."""


def first_hour_block() -> str:
    """The shell block under the README's '## Your first hour'."""
    section = (ROOT / "README.md").read_text().split("## Your first hour", 1)[1]
    match = re.search(r"```sh\n(.*?)```", section, re.DOTALL)
    assert match, "the first hour has no sh block"
    return match.group(1)


@pytest.mark.heavy  # minutes: two launches, two goals, a report of two runs, a replay
def test_the_first_hour_of_the_readme_runs_as_written(tmp_path: Path) -> None:
    """In a folder of its own (``deploy`` and ``.venv`` as the root has them), ``bash -e``: every
    command exits 0, the goals are reached, the recording is whole and holds them, the reports
    are written (the rerun's labelled as such), the layout is Foxglove's, the replay ends and
    the emulated hardware starts and stops."""
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
    # the cascade re-run on the recording's states, beside the LP in one report, which says
    # the rerun's commands were not in a closed loop (on stderr, in the table, in the verdict)
    assert (tmp_path / "cascade.mcap").is_file()
    note = (
        "cascade (rerun): its commands were computed by `parsimony rerun` on the "
        "recording's states, not in a closed loop"
    )
    assert note in result.stderr, result.stderr[-3000:]
    assert f"Note: {note}" in (tmp_path / "compare" / "effort.md").read_text()
    judged = json.loads((tmp_path / "compare" / "judged.json").read_text())
    assert {label: run["open_loop"] for label, run in judged.items()} == {
        "lp": False,
        "cascade (rerun)": True,
    }, judged.keys()
    # the live view served on the profile's port, and stopped after its duration
    assert "view: sim live at ws://127.0.0.1:8765" in result.stderr, result.stderr[-3000:]
    assert "messages shown" in result.stderr
    # the view's layout, on the profile's namespace (its publish-pose tool on goal/request)
    layout = json.loads((tmp_path / "station.json").read_text())
    assert "sim/goal/request" in json.dumps(layout["content"])
    # the emulated hardware: the drivers on the emulated devices, stopped after its duration
    for driver in ("base_driver", "arm_driver"):
        assert f"[launch] {driver} alive" in result.stderr, result.stderr[-3000:]
    assert "[launch] stopping (end of duration)" in result.stderr
    assert "Traceback" not in result.stderr
