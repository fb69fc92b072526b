"""`parsimony bench --zoo`: a robot description that cannot be used stops the bench before any
timing, with one line naming the file and what is wrong."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.parsimony.in_process import run_in_process


def test_a_description_that_cannot_be_used_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("arm: 3\n")
    code, out, err = run_in_process(["bench", "--zoo-only", "--zoo", str(bad)], capsys)
    assert code == 2 and out == ""
    [line] = err.strip().splitlines()
    assert line.startswith(f"parsimony bench: {bad}: arm")
