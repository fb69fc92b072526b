"""The start-up bench (studies/bench/startup.py): what it starts, and its report as JSON."""

from __future__ import annotations

import json

import pytest

from studies.bench.startup import main, starts


def test_every_component_module_and_the_commands_are_measured() -> None:
    names = starts()
    assert {"components.lp_controller", "components.supervisor", "parsimony --help"} <= set(names)
    assert "components.runtime" not in names  # no process of its own
    assert names["parsimony status --help"][1:] == ["-m", "parsimony.cli", "status", "--help"]


def test_the_bench_prints_the_cost_of_a_start_as_json(capsys: pytest.CaptureFixture[str]) -> None:
    """One start (a module of no component of the bench's profile: none is launched)."""
    assert main(["--runs", "1", "--json", "--only", "scripted_publisher"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["components"] == {}
    assert list(report["starts"]) == ["components.scripted_publisher"]
    cost = report["starts"]["components.scripted_publisher"]
    assert cost["wall_ms"]["n"] == cost["cpu_ms"]["n"] == 1
    assert cost["wall_ms"]["median"] > 0 and cost["cpu_ms"]["median"] > 0
