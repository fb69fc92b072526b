"""One study's tables in several docs pages (a table's own ``page``), each table over the runs
it names (``where``), a law that runs some of the study's tasks only (``task``), and the
figures the results pages need beside the others: the nonzero entries near the goal with x'
and y' as one, the goals not reached by reason, and the arm's penetrations and clearances."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
import yaml

from parsimony.cli import main
from studies.goal_sets import Attempt
from studies.study.figures import KINEMATIC, SIMULATED
from studies.study.report import check_tables, markers, pages
from studies.study.schema import StudyError, load_study
from studies.study.sweep import expand
from wbc.robot import MobileManipulator

ROOT = Path(__file__).resolve().parents[3]
MARKED = "# A page\n\n<!-- study two-pages: made by parsimony study -->\nold\n"
MARKED += "<!-- end of study two-pages -->\n\nThe prose after it.\n"


def two_pages(directory: Path) -> dict:
    """One goal ahead, its pose and its position, the LP on both and the supervised LP on the
    pose only; a table per page, each over the runs it names."""
    return {
        "name": "two-pages",
        "families": ["ahead"],
        "task": ["pose", "position"],
        "goals": 1,
        "seeds": [2],
        "laws": [
            {"law": "lp", "label": "LP"},
            {"law": "lp + staging supervisor", "label": "supervised", "task": "pose"},
        ],
        "page": str(directory / "first.md"),
        "tables": [
            {
                "title": "poses",
                "by": ["task", "law"],
                "where": {"task": ["pose"]},
                "figures": ["runs", "reached", "nonzero near the goal, x' y' as one"],
            },
            {
                "title": "the LP",
                "page": str(directory / "second.md"),
                "by": ["task", "law"],
                "where": {"law": ["LP"]},
                "figures": ["runs", "reached", "not reached"],
            },
        ],
    }


def write(directory: Path, study: dict) -> Path:
    file = directory / f"{study['name']}.yaml"
    file.write_text(yaml.safe_dump(study))
    return file


def test_a_law_of_its_own_task_runs_that_task_only(tmp_path) -> None:
    study = load_study(write(tmp_path, two_pages(tmp_path)))
    runs = [(run.parameters["task"], run.parameters["law"]) for run in expand(study)]
    assert runs == [("pose", "LP"), ("pose", "supervised"), ("position", "LP")]


def test_each_page_gets_its_own_tables_over_the_runs_they_name(tmp_path, capsys) -> None:
    file = write(tmp_path, two_pages(tmp_path))
    for page in ("first.md", "second.md"):
        (tmp_path / page).write_text(MARKED)
    path = tmp_path / "two-pages.parquet"
    assert main(["study", str(file), "--workers", "2", "--results", str(path)]) == 0
    capsys.readouterr()
    assert main(["study", str(file), "--results", str(path), "--report", "--page"]) == 0
    out = capsys.readouterr().out
    assert "**poses**" in out and "**the LP**" in out  # stdout: every table
    first, second = ((tmp_path / page).read_text() for page in ("first.md", "second.md"))
    for text in (first, second):
        assert f"parsimony study {file} --report" in text and "3 of 3 runs" in text
        assert text.startswith("# A page") and text.endswith("The prose after it.\n")
        assert "old" not in text
    assert "**poses**" in first and "the LP" not in first
    assert "**the LP**" in second and "poses" not in second
    poses = [line.split("|")[1:3] for line in first.splitlines() if line.startswith("| pose")]
    assert [[cell.strip() for cell in line] for line in poses] == [
        ["pose", "LP"],
        ["pose", "supervised"],
    ]
    lines = [line for line in second.splitlines() if line.startswith("| p")]
    assert [line.split("|")[1].strip() for line in lines] == ["pose", "position"]
    assert "nonzero near the goal, x' y' as one |" in first


def test_a_page_without_the_studys_markers_is_one_line(tmp_path, capsys) -> None:
    file = write(tmp_path, two_pages(tmp_path))
    (tmp_path / "first.md").write_text(MARKED)
    (tmp_path / "second.md").write_text("# No markers\n")
    assert (
        main(
            ["study", str(file), "--results", str(tmp_path / "none.parquet"), "--report", "--page"]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "second.md" in err and "first.md" not in err, err


@pytest.mark.parametrize(
    ("where", "said"),
    [({"law": ["LQ"]}, "no law 'LQ' in the study"), ({"colour": ["red"]}, "no parameter")],
)
def test_a_table_over_runs_nobody_has_is_refused(tmp_path, where, said) -> None:
    study = two_pages(tmp_path)
    study["tables"][0]["where"] = where
    with pytest.raises(StudyError, match=said):
        check_tables(load_study(write(tmp_path, study)))


def test_a_task_of_its_own_is_one_of_the_studys(tmp_path) -> None:
    study = two_pages(tmp_path) | {"task": "position"}
    with pytest.raises(StudyError, match="none of its tasks is the study's"):
        load_study(write(tmp_path, study))


def test_the_arms_figures_count_penetrating_runs_and_keep_each_parts_least_clearance() -> None:
    """Two whole-loop runs' reports (the judge's ``arm_penetrations`` and ``arm_clearance_m``),
    and a failed run, which counts for neither."""
    reports = [
        {"arm_penetrations": 2, "arm_clearance_m": {"gripper": -0.055, "wrist": 0.031}},
        {"arm_penetrations": 0, "arm_clearance_m": {"gripper": 0.026, "wrist": 0.063}},
    ]
    rows = [{"status": "ok", "report": json.dumps(report)} for report in reports]
    rows.append({"status": "failed", "report": None})
    robot = MobileManipulator.from_yaml(ROOT / "deploy/robots/little_john.yaml")
    assert SIMULATED["arm penetrations"](rows, robot) == {"with an arm penetration": 1}
    assert SIMULATED["arm clearance"](rows, robot) == {"gripper (m)": -0.055, "wrist (m)": 0.031}


def test_whole_loop_runs_not_converged_are_counted_by_the_supervisors_reason() -> None:
    """Two runs left out for one kind of reason (each naming its count) and a converged run
    and a run without a supervisor, which count for none."""
    reason = "every whole-body configuration found that reaches the goal ({n}) is left out: "
    reports = [
        {"converged": False, "supervisor": {"reason": reason.format(n=40)}},
        {"converged": False, "supervisor": {"reason": reason.format(n=38)}},
        {"converged": True, "supervisor": {"reason": ""}},
        {"converged": False, "supervisor": None},
    ]
    rows = [{"status": "ok", "report": json.dumps(report)} for report in reports]
    robot = MobileManipulator.from_yaml(ROOT / "deploy/robots/little_john.yaml")
    assert SIMULATED["not reached"](rows, robot) == {
        "every whole-body configuration found that reaches the goal is left out": 2
    }


def test_the_goals_not_reached_are_counted_by_the_kind_of_their_reason() -> None:
    """Two goals left out for the same kind of reason, each naming its own count, are one
    kind; a goal reached has no reason."""
    left_out = "every whole-body configuration found that reaches the goal ({n}) is left out: "
    left_out += "{n} bring the base within 0.05 m of an obstacle"
    reasons = [left_out.format(n=18), left_out.format(n=9), "time limit in turn", ""]
    rows = [
        dataclasses.asdict(Attempt(not reason, 1, 0.0, 0.0, (), (), (), reason=reason))
        | {"status": "ok"}
        for reason in reasons
    ]
    robot = MobileManipulator.from_yaml(ROOT / "deploy/robots/little_john.yaml")
    assert KINEMATIC["not reached"](rows, robot) == {
        "every whole-body configuration found that reaches the goal is left out": 2,
        "time limit in turn": 1,
    }


@pytest.mark.parametrize(
    "file", sorted((ROOT / "studies/files").glob("*.yaml")), ids=lambda p: p.stem
)
def test_every_study_file_of_the_docs_is_a_study_whose_tables_its_runs_fill(file: Path) -> None:
    """Each study file loads, and its tables name parameters, values and figures it has; each
    page it writes into has the study's block."""
    study = load_study(file)
    check_tables(study)
    for page in pages(study):
        assert markers(study)[0] in (ROOT / page).read_text(), page
