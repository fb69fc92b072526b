"""The goal reach bench: a row per set and law, and each law's misses said by kind."""

from __future__ import annotations

import json
import subprocess
import sys

WIDE = "ahead, wide arm"


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "studies.bench.goal_reach", *args],
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_the_bench_says_how_often_each_law_reaches_each_set_and_why_it_misses() -> None:
    """Goals with the arm bent back over the base: the LP alone misses one of the four of
    seed 2, its base turned away, where the supervised LP reaches all; the family's summary
    says so over its sets."""
    done = run(
        "--families",
        WIDE,
        "--seeds",
        "2",
        "--goals",
        "4",
        "--variant",
        "base_target_stop=0.25",
        "--supervised",
        "--json",
    )
    assert done.returncode == 0, done.stderr[-2000:]
    report = json.loads(done.stdout)  # the JSON alone on stdout
    rows = {row["law"]: row for row in report["rows"]}
    assert rows.keys() == {"lp", "base_target_stop=0.25", "lp + staging supervisor"}
    assert rows["lp"]["reached inside every limit"] == 0.75
    assert rows["lp + staging supervisor"]["reached inside every limit"] == 1.0
    misses = {row["law"]: row for row in report["misses"]}
    assert misses["lp"]["missed"] == 1 and misses["lp"]["base heading off"] == 1
    assert misses["lp"]["seeds"] == "2" and misses["lp"]["goals"] == 4
    assert misses["lp"]["reached"] == misses["lp"]["worst set"] == 0.75
    assert misses["lp + staging supervisor"]["reached"] == 1.0
    assert misses["lp"]["nonzero moving"] <= 7
    assert "missed" not in misses["lp + staging supervisor"]
    assert f"bench: {WIDE}, seed 2" in done.stderr  # progress goes to stderr


def test_a_gain_the_lp_does_not_have_is_one_line() -> None:
    done = run("--variant", "base_target_stop=-1", "--goals", "1")
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.count("\n") == 1 and "base_target_stop" in done.stderr, done.stderr
