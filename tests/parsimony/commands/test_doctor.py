"""`parsimony doctor PROFILE` against emulated devices: exit 0 and the checklist as JSON on
stdout alone when all is well, exit 1 and the fault with its fix when not."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from parsimony.cli import main
from tests.launch.doctor_bench import Setup, bench


def test_all_well_is_exit_0_and_the_checklist_as_json_on_stdout(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with bench(tmp_path, Setup()) as devices:
        code = main(["doctor", str(devices.profile), "--json"])
    out = capsys.readouterr().out
    report = json.loads(out)
    assert code == 0 and report["ok"] is True
    assert {check["status"] for check in report["checks"]} <= {"ok", "warn"}
    names = [check["name"] for check in report["checks"]]
    assert "servo 1 (q1)" in names and "create" in names and "reference marker" in names


def test_a_fault_is_exit_1_and_its_line_says_the_fix(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with bench(tmp_path, Setup(baud=57_600)) as devices:
        code = main(["doctor", str(devices.profile)])
    out = capsys.readouterr().out
    assert code == 1
    assert "FAIL  servo 1 (q1): no answer at id 1 at 1000000 baud" in out
    assert "fix: set arm_driver's baud: 57600" in out
    assert ": 5 faults" in out.rstrip().splitlines()[-1]


def test_a_profile_that_is_not_there_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["doctor", str(tmp_path / "none.yaml")]) == 2
    err = capsys.readouterr().err
    assert "none.yaml" in err and "Traceback" not in err
