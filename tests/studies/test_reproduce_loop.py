"""`parsimony reproduce --loop` as a user runs it: the set-ups of 6.2 on the whole simulated loop,
their rows read back from the recordings beside the kinematic ones (a file of its own, so that a
second worker runs it beside the kinematic reproduction)."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest

from analysis.commands import commands
from analysis.judge import JUDGED
from analysis.run_end import messages, the_run
from messages.topics import CONTROL_DIAGNOSTICS
from profiles.deploy_files import ROBOT_FILE
from record.sessions import load_session
from studies.reproduce.loop import folder
from studies.reproduce.runs import laws_of
from tests.parsimony.in_process import completed, run_in_process
from wbc.robot import MobileManipulator

pytestmark = pytest.mark.heavy  # the whole loop, twice


LOOP_LAWS = ("LP 5.29", "cascade, saturated")
"""The laws the test runs on the loop, for 2 simulated seconds of the pose set-up."""


def test_the_loop_prints_the_rows_of_its_recordings_beside_the_kinematic_ones(
    tmp_path: Path,
) -> None:
    """`reproduce --loop`: each law runs the pose set-up on the whole loop with the gains of its
    kinematic run (the recording says which), and its rows, read back from the recording,
    follow the kinematic ones; the command says how long the loop took. (Its figures, which
    test_reproduce reads, are not drawn: ``--no-figures``.)"""
    laws = [argument for label in LOOP_LAWS for argument in ("--law", label)]
    done = completed(
        "reproduce",
        "--json",
        "--loop",
        "--only",
        "pose",
        *laws,
        "--time-limit",
        "2",
        "--no-figures",
        "--out",
        str(tmp_path),
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert not list(tmp_path.rglob("*.png")) and not (tmp_path / "NOTES.md").exists()
    found = json.loads(done.stdout)
    rows = found["rows"]
    keys = [row["key"] for row in rows]
    assert {row["experiment"] for row in rows} <= {"pose", "pose on the loop"}
    for index, row in enumerate(rows):  # each after its kinematic row, or another of the loop
        if row["key"].startswith("loop.") and row["key"][5:] in keys:
            before = keys[keys.index(row["key"][5:]) : index]
            assert all(key.startswith("loop.") for key in before[1:]), (row["key"], before)
    ran = {(law["experiment"], law["label"]): law["ran"] for law in found["laws"]}
    robot = MobileManipulator.from_yaml(ROBOT_FILE)
    for label in LOOP_LAWS:
        assert ran["pose on the loop", label].startswith("the whole loop in lockstep")
        session = load_session(tmp_path / "loop" / "pose" / folder(label) / "session.mcap", JUDGED)
        run, _ = the_run(session, 2.0)
        stamps, u = commands(run)
        diagnostics = [
            d
            for d in messages(run, CONTROL_DIAGNOSTICS)
            if d.header.stamp_ns in set(stamps.tolist())
        ]
        first = next(i for i, d in enumerate(diagnostics) if d.status == "optimal")
        steps = diagnostics[first:]
        assert steps[-1].parameters == asdict(laws_of(robot, "pose")[label].params)
        row = {
            key[5:]: r["ours"] for key, r in zip(keys, rows, strict=True) if key.startswith("loop.")
        }
        assert row["pose.converged"][label] == [False, len(steps)]
        index = list(stamps).index(steps[0].header.stamp_ns)
        assert row[f"pose.first_step.{label}"]["u"] == [round(float(v), 3) for v in u[index]]
        solve_ms = np.array([d.solve_time_us for d in steps]) / 1e3
        assert row[f"step_time.{label}"]["p99"] == pytest.approx(np.percentile(solve_ms, 99))
        assert row[f"step_time.{label}.handler"]["pose"][1] > 0.0
    loop = found["loop"]
    assert [run["label"] for run in loop["runs"]] == list(LOOP_LAWS)
    assert loop["wall_s"] > 0.0 and loop["sim_s"] == pytest.approx(4.0, abs=0.1)


def test_the_laws_of_the_loop_need_the_loop(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run_in_process(["reproduce", "--law", "LP", "--out", str(tmp_path)], capsys)
    assert code == 2 and out == "", err
    assert "--law chooses the laws of the loop: add --loop" in err
    assert not any(tmp_path.iterdir())
