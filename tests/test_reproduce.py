"""`parsimony reproduce` as a user runs it: every result of chapter 6 is a row, beside the
dissertation's value, and every figure is written."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from parsimony.reproduce import NOTES, TABLE_6_1

RESULTS = {
    "6.2.1": ("pose task: converged", "fig. 6.7: median nonzero entries of u, LP, while",
              "fig. 6.7: LP, last 2 s", "fig. 6.7: PINV", "fig. 6.8:", "fig. 6.10:"),
    "6.2.2": ("position task: converged", "fig. 6.12: median nonzero", "fig. 6.12: PINV",
              "fig. 6.13:"),
    "6.2.3": ("obstacle, the vector-field inequality: converged", "obstacle, 5.28: converged",
              "fig. 6.17, the vector-field", "fig. 6.17, 5.28"),
    "6.3": ("test 1 (holonomic): iterations", "test 1: ms per iteration",
            "test 2 (nonholonomic): iterations", "test 2: ms per iteration"),
    "7.2 (1)": ("pose: LP with the input change term against without, iterations",
                "pose: LP with the input change term against without, metric 4 from rest",
                "position: LP with the input change term against without, metric 3"),
}  # fmt: skip


def test_reproduce_sets_every_chapter_6_result_beside_ours(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, "-m", "parsimony.cli", "reproduce", "--json",
                           "--trials", "1", "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)  # the JSON alone on stdout
    rows = report["rows"]
    for section, results in RESULTS.items():
        mine = [row["result"] for row in rows if row["section"] == section]
        for result in results:
            assert any(r.startswith(result) for r in mine), (section, result, mine)
    table = [row for row in rows if row["section"] == "table 6.1"]
    for task, laws in TABLE_6_1.items():
        for metric in range(4):
            found = [row for row in table if row["result"].startswith(f"{task}, metric "
                                                                       f"{metric + 1}")]
            assert len(found) == 3, (task, metric)  # as run, same time, both meeting J u
            for row in found:
                assert row["dissertation"]["LP"] == laws["LP"][metric]
                assert row["dissertation"]["PINV"] == laws["PINV"][metric]
                assert row["ours"]["LP/PINV"] == row["ours"]["LP"] / row["ours"]["PINV"]
                assert row["direction"] in ("LP lower (1-norm)", "PINV lower (2-norm)")
    for row in rows:
        assert row["ours"] is not None and row["dissertation"] is not None, row
    for path in report["figures"]:
        assert Path(path).stat().st_size > 1000, path
    notes = (tmp_path / "NOTES.md").read_text()
    for name in NOTES:
        assert (tmp_path / name).is_file() and f"`{name}`" in notes
