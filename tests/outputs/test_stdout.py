"""What a command prints on its standard output (outputs/stdout.py): standard JSON, plain tables.
(That a library's writes to fd 1 reach stderr while a command runs is tested in
tests/parsimony/test_cli.py.)"""

from __future__ import annotations

import math

from outputs.stdout import finite, json_text, table


def test_json_writes_a_nan_or_an_infinity_as_null_at_any_depth() -> None:
    value = {"median": math.nan, "rows": [(1.0, -math.inf)], "n": 3}
    assert json_text(value) == '{"median": null, "rows": [[1.0, null]], "n": 3}'
    assert finite(2.5) == 2.5


def test_a_table_shows_a_missing_value_as_a_dash() -> None:
    lines = table([{"law": "lp", "steps": 10}, {"law": "qp"}]).splitlines()
    assert lines[0].split() == ["law", "steps"] and lines[2].split() == ["qp", "-"]
