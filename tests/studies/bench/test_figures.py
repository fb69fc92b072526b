"""The figures a benchmark prints of a sample and its command line (studies/bench/figures.py)."""

from __future__ import annotations

import json

import pytest

from studies.bench.figures import run_bench, spread


def test_a_sample_is_its_median_p99_and_maximum_rounded() -> None:
    assert spread([1.0, 2.0, 3.0, 10.0]) == {"median": 2.5, "p99": 9.8, "max": 10.0, "n": 4}
    assert spread([1.234], digits=2)["median"] == 1.23
    assert spread([]) == {"median": None, "p99": None, "max": None, "n": 0}


def measure(runs: int) -> dict:
    return {"runs": runs, "latency_us": spread([5.0] * runs)}


def lines(report: dict) -> list[str]:
    return [f"{report['runs']} runs, median {report['latency_us']['median']} us"]


def test_a_benchmark_prints_its_lines_or_its_report_as_json(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert run_bench("A benchmark.\n\nMore.", measure, lines, 3, []) == 0
    assert capsys.readouterr().out == "3 runs, median 5.0 us\n"
    run_bench("A benchmark.", measure, lines, 3, ["--runs", "2", "--json"])
    assert json.loads(capsys.readouterr().out)["latency_us"]["n"] == 2
