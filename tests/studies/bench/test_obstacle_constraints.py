"""The obstacle constraints' bench: one row per law and loop, counted from the runs."""

from __future__ import annotations

import json
import subprocess
import sys

from studies.bench.obstacle_constraints import VARIANTS


def test_the_bench_prints_one_row_per_constraint_as_json_alone() -> None:
    """One kinematic seed, no simulated one: a row for each variant. 5.19 stops the base
    before the obstacle by design, so it is counted as not converged, naming the seed."""
    command = [
        sys.executable,
        "-m",
        "studies.bench.obstacle_constraints",
        "--seeds",
        "0",
        "--kinematic-seeds",
        "1",
        "--workers",
        "1",
        "--json",
    ]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    report = json.loads(done.stdout)
    rows = {row["constraint"]: row for row in report["variants"]}
    assert rows.keys() == VARIANTS.keys()
    assert {row["loop"] for row in rows.values()} == {"kinematic"}
    for row in rows.values():
        assert row["runs"] == 1 and row["did_not_run"] == 0
        assert row["with_contact"] == 0 and row["least_clearance_m"] > 0.0
        assert 1 <= row["nonzero_moving"] <= 8
    stopped = rows["5.19, 5.7"]
    assert stopped["converged"] == 0.0 and stopped["not_converged"][0].startswith("0(")
    assert rows["VFI + circulation, 5.7"]["converged"] == 1.0
    assert "[bench] kinematic" in done.stderr  # progress goes to stderr
