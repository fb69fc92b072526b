"""What a study may run besides goal families, each on a tiny study in this process: an
experiment's set-up kinematically (the obstacle constraints compared), the zoo's goals (its
table and plot), a law compared goal by goal with another (the input change term); and the
sweep of both loops with seeds by loop and ranges of seeds."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from analysis.judge import recording_check
from messages.topics import ROBOT_STATE
from parsimony.cli import main
from record.session_reader import info
from studies.study import results
from studies.study.plots import draw
from studies.study.report import markdown
from studies.study.runs import whole_recording
from studies.study.schema import StudyError, load_study
from studies.study.sweep import expand

ROOT = Path(__file__).resolve().parents[3]


def run(tmp_path: Path, capsys, study: dict) -> tuple[list[dict], str]:
    """``study`` run on the local pool of two, and its report: the rows of each table (a dict
    per line) and the report's text."""
    file = tmp_path / f"{study['name']}.yaml"
    file.write_text(yaml.safe_dump(study))
    path = tmp_path / "results.parquet"
    assert main(["study", str(file), "--workers", "2", "--results", str(path)]) == 0
    assert {row["status"] for row in results.read(path)} == {"ok"}
    capsys.readouterr()
    assert main(["study", str(file), "--results", str(path), "--report"]) == 0
    text = capsys.readouterr().out
    lines = [line for line in text.splitlines() if line.startswith("|")]
    header = [cell.strip() for cell in lines[0].strip("|").split("|")]
    rows = [
        dict(zip(header, (cell.strip() for cell in line.strip("|").split("|")), strict=True))
        for line in lines[2:]
        if not line.startswith("|:")
    ]
    return rows, text


def test_the_obstacle_experiments_set_up_compares_constraints_kinematically(
    tmp_path, capsys
) -> None:
    """Seed 0 of the obstacle experiment: the experiment's law (VFI and circulation)
    converges clear of the obstacle, moving all 8 entries; 5.19 stops the base before it by
    design, with 3, and its seed is said with its final error."""
    study = {
        "name": "obstacles",
        "experiments": ["obstacle"],
        "seeds": ["0-0"],
        "laws": [
            {"law": "lp", "label": "VFI"},
            {"law": "lp", "label": "5.19", "gains": {"obstacle_mode": "conservative"}},
        ],
        "tables": [
            {
                "title": "obstacle",
                "by": ["law"],
                "seeds": [0],
                "figures": ["converged", "not converged", "least clearance", "with a contact"]
                + ["nonzero moving", "time to converge"],
            }
        ],
    }
    rows, _ = run(tmp_path, capsys, study)
    vfi, conservative = rows
    assert (vfi["law"], vfi["converged"], vfi["not converged (final error)"]) == ("VFI", "1", "")
    assert float(vfi["least clearance (m)"]) > 0.1 and vfi["with a contact"] == "0"
    assert vfi["nonzero moving"] == "8" and 5.0 < float(vfi["time to converge, median (s)"]) < 60
    assert conservative["converged"] == "0" and conservative["nonzero moving"] == "3"
    assert conservative["not converged (final error)"].startswith("0 (0.")


def test_the_zoos_goals_give_its_table_and_plot(tmp_path, capsys) -> None:
    """One goal of the zoo on Little John, as a pose and a position: the pseudoinverse moves
    every entry with no constraint engaged, the LP at most the task's DOF plus the constraints
    it engages; the plot is a PNG."""
    study = yaml.safe_load((ROOT / "studies/files/redundancy.yaml").read_text())
    study |= {"robots": ["little_john"], "goals": 1, "page": None}
    study["laws"] = [{"law": "lp"}, {"law": "pinv"}]
    rows, text = run(tmp_path, capsys, study)
    assert [(r["task"], r["law"]) for r in rows] == [
        ("pose", "lp"),
        ("pose", "pinv"),
        ("position", "lp"),
        ("position", "pinv"),
    ]
    for row in rows:
        assert (row["base"], row["entries"]) == ("differential", "8")
        if row["law"] == "pinv":
            assert (row["nonzero moving"], row["engaged moving"]) == ("8", "0")
            assert row["<= task + engaged"] == "0"
        else:
            task = 6 if row["task"] == "pose" else 3
            assert int(row["nonzero moving"]) <= task + int(row["engaged moving"])
    file = tmp_path / "study.yaml"
    file.write_text(yaml.safe_dump(study))
    loaded = load_study(file)
    plot = loaded.plots[0].model_copy(update={"file": tmp_path / "zoo.png"})
    rows_found = results.read(tmp_path / "results.parquet")
    drawn = draw(loaded, plot, expand(loaded, tmp_path), rows_found)
    assert drawn.read_bytes()[:4] == b"\x89PNG"


def test_a_law_is_compared_goal_by_goal_with_another(tmp_path, capsys) -> None:
    """The input change term against the LP on one goal ahead: the LP's ratios are 1, the
    term's jump from rest (metric 4 from rest) is smaller than the LP's."""
    study = yaml.safe_load((ROOT / "studies/files/smoother-inputs.yaml").read_text())
    study |= {"goals": 1, "task": "pose", "page": None, "laws": study["laws"][:2]}
    rows, _ = run(tmp_path, capsys, study)
    lp, term = rows
    assert lp["goals compared"] == term["goals compared"] == "1"
    assert lp["metric 4 from rest, ratio"] == lp["metric 3, ratio"] == "1"
    assert float(term["metric 4 from rest, ratio"]) < 1.0


def test_both_loops_sweep_each_set_up_with_their_own_seeds() -> None:
    """The obstacle study: the kinematic loop's 200 seeds, the whole loop's 41, six laws; the
    loop is a parameter of each run, and only a simulated run has a directory."""
    study = load_study(ROOT / "studies/files/obstacles.yaml")
    runs = expand(study, ROOT / "studies/files", Path("runs/studies/obstacles"))
    loops = [run.parameters["loop"] for run in runs]
    assert (loops.count("kinematic"), loops.count("simulated")) == (6 * 200, 6 * 41)
    assert json.loads(runs[0].key)[0] == "kinematic" and runs[0].out == ""
    assert {run.parameters["seed"] for run in runs if run.loop == "simulated"} == {
        772,
        *range(40),
    }
    assert all(run.out for run in runs if run.loop == "simulated")
    assert "0 of 1446 runs" in markdown(study, "obstacles.yaml", runs, [])


@pytest.mark.parametrize("seeds", [["5-2"], ["a-b"]])
def test_a_range_of_seeds_that_is_none_is_one_line(tmp_path, seeds) -> None:
    file = tmp_path / "bad.yaml"
    study = {"name": "bad", "families": ["ahead"], "seeds": seeds, "laws": [{"law": "lp"}]}
    file.write_text(yaml.safe_dump(study))
    with pytest.raises(StudyError, match="neither a seed nor a range") as error:
        load_study(file)
    assert "\n" not in str(error.value)


def test_rows_of_both_loops_keep_each_its_columns(tmp_path) -> None:
    """A kinematic row and a simulated one in one file: each keeps the columns the other has
    not (pyarrow takes a table's columns from its first row unless told)."""
    path = tmp_path / "both.parquet"
    rows = [{"index": 1, "key": "b", "report": "{}"}, {"index": 0, "key": "a", "goal_q": [1.0]}]
    results.write(path, rows)
    assert results.read(path) == [
        {"index": 0, "key": "a", "goal_q": [1.0], "report": None},
        {"index": 1, "key": "b", "goal_q": None, "report": "{}"},
    ]


def test_a_whole_loop_run_whose_recording_is_cut_short_is_a_failure_that_says_why(
    pose_lp_run: Path,
) -> None:
    """A run judged from a recording that lost its last states would be judged wrongly (seen:
    a converged run judged not converged, its recorder starved of CPU): the study records it
    failed, with what is missing, and tries it again."""
    report = json.loads((pose_lp_run / "report.json").read_text())
    whole_recording(report)  # the whole run: a row of figures
    facts = info(pose_lp_run / "session.mcap")
    states = [c for c in facts["channels"] if c["key"].endswith("/" + ROBOT_STATE.name)]
    start_ns, last_ns = states[0]["start_ns"], states[0]["end_ns"]
    report["recording"] = recording_check(facts, (start_ns, last_ns + 440_000_000))
    with pytest.raises(RuntimeError, match="not whole: its states end 0.44 s before the run's"):
        whole_recording(report)
