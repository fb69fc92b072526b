"""A result of `parsimony reproduce` and the tables it prints (studies/reproduce/table.py)."""

from __future__ import annotations

from studies.reproduce.table import Row, format_rows, shown


def test_values_are_shown_to_four_significant_digits_at_any_depth() -> None:
    assert shown(0.123456) == "0.1235" and shown(12345.6) == "1.235e+04"
    assert shown([1.0, 2.5e-7]) == "[1, 2.5e-07]"
    assert shown({"moving": [3.0, 2.0], "steps": 7}) == "moving [3, 2], steps 7"


def test_a_row_sets_ours_beside_the_dissertations_as_text() -> None:
    rows = [Row("pose.steps", "6.2.1", "steps to converge", 1021, 880.123456, "fewer")]
    header, line = format_rows(rows).splitlines()
    assert header.split() == ["section", "result", "dissertation", "ours", "should", "be"]
    assert line.split() == ["6.2.1", "steps", "to", "converge", "1021", "880.1", "fewer"]
