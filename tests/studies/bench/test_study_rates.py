"""The study rates bench refuses counts below one in one line (its measures run by hand: a
whole-loop study and a Dask cluster are not a unit test's)."""

from __future__ import annotations

import pytest

from studies.bench.study_rates import main


@pytest.mark.parametrize("argv", [["--workers", "0"], ["--workers", "x"], ["--goals", "0"]])
def test_counts_below_one_are_one_line_and_exit_2(argv, capsys) -> None:
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.strip().splitlines()) == 1 and "Traceback" not in err
