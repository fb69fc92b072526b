"""Standard output carries a command's result and nothing else (outputs/stdout.py)."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

from outputs.stdout import finite, json_text, table

ROOT = Path(__file__).resolve().parents[2]

NOISY = """
import os
from outputs.stdout import emit, result_only_stdout
with result_only_stdout():
    print("a log line")
    os.write(1, b"a banner from C\\n")
    emit('{"ok": true}')
print("after")
"""


def test_while_a_command_runs_only_its_result_reaches_stdout() -> None:
    done = subprocess.run(
        [sys.executable, "-c", NOISY],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    assert done.stdout == '{"ok": true}\nafter\n'
    assert "a log line" in done.stderr and "a banner from C" in done.stderr


def test_json_writes_a_nan_or_an_infinity_as_null_at_any_depth() -> None:
    value = {"median": math.nan, "rows": [(1.0, -math.inf)], "n": 3}
    assert json_text(value) == '{"median": null, "rows": [[1.0, null]], "n": 3}'
    assert finite(2.5) == 2.5


def test_a_table_shows_a_missing_value_as_a_dash() -> None:
    lines = table([{"law": "lp", "steps": 10}, {"law": "qp"}]).splitlines()
    assert lines[0].split() == ["law", "steps"] and lines[2].split() == ["qp", "-"]
