"""The hyper-redundant study: goals reachable by construction, what it says of each law's
nonzero entries of u on a small sample of two robots of the zoo, and its command
(studies.bench.redundancy): JSON alone on stdout, its table on stderr, a figure, and reports
merged without running again."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from profiles.deploy_files import DEPLOY, zoo
from studies import redundancy
from studies.bench.redundancy import main
from studies.redundancy import BASE_MOVE, TASKS, arm_box, draw, engaged_count, task_of
from wbc.geometry.scenarios import DT
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.robot import BASE_DOF, MobileManipulator

ROBOTS = DEPLOY / "robots"
LITTLE_JOHN, SNAKE, SEVEN = (
    ROBOTS / f"{name}.yaml" for name in ("little_john", "snake12", "arm7_differential")
)


def test_the_zoo_is_every_description_and_the_study_runs_them_all() -> None:
    assert {LITTLE_JOHN, SNAKE, SEVEN} <= set(zoo())


def test_goals_are_configurations_inside_every_limit_drawn_from_a_fixed_seed() -> None:
    """Start and goal arms in the LP's joint box and the limits, every frame above the floor,
    the goal's base moved as the bench's goals ahead; the same seed, the same goals. Where a
    range does not straddle zero (the Panda's q4) the box lies inside the limit too."""
    robot = MobileManipulator.from_yaml(SEVEN)
    pairs = draw(robot, 5)
    low, high = arm_box(robot)
    assert robot.q_min[BASE_DOF + 3] < low[3] < high[3] < robot.q_max[BASE_DOF + 3] < 0.0
    for (start, goal), (again, _) in zip(pairs, draw(robot, 5), strict=True):
        assert np.array_equal(start, again)
        for q in (start, goal):
            assert np.all(low <= q[BASE_DOF:]) and np.all(q[BASE_DOF:] <= high)
            assert robot.link_points(q)[:, 2].min() > 0.0
        assert np.array_equal(start[:BASE_DOF], np.zeros(3))
        assert BASE_MOVE.distance[0] <= math.hypot(*goal[:2]) <= BASE_MOVE.distance[1]


def test_the_lp_of_5_29_uses_at_most_the_tasks_dof_plus_the_constraints_engaged() -> None:
    """On the 15-DOF snake, every step of 5.29 (the default LP without its base target, whose
    residual rows are rows of the program too): nonzero entries <= 6 + engaged."""
    robot = MobileManipulator.from_yaml(SNAKE)
    start, goal = draw(robot, 1)[0]
    law, task = LPLaw(robot, LPParams(base_target=0.0)), task_of(robot, goal, "pose")
    q, counts = start, []
    for _ in range(40):
        out = law.step(q, task, DT)
        assert out.nonzero <= TASKS["pose"] + engaged_count(out)
        counts.append(out.nonzero)
        q = q + out.u * DT
    assert max(counts) < robot.dof


def test_on_two_robots_the_pseudoinverse_moves_every_entry_the_lp_what_its_rows_allow() -> None:
    """Half a second of each law towards one goal of each family: the report's structure;
    while moving, the pseudoinverse's median count is the robot's DOF with no constraint
    engaged, the LP's at most the task's DOF plus the constraints it engages (5.12 at least)."""
    report = redundancy.study([LITTLE_JOHN, SNAKE], count=1, workers=1, time_limit_s=0.5)
    assert list(report) == ["little_john", "snake12"]
    for name, dof, mobility in (("little_john", 8, 7), ("snake12", 15, 14)):
        robot = report[name]
        assert (robot["dof"], robot["mobility"], robot["base"]) == (dof, mobility, "differential")
        assert set(robot["families"]) == set(TASKS)
        for family, laws in robot["families"].items():
            assert set(laws) == {"lp", "qp", "pinv"}
            pinv, lp = laws["pinv"], laws["lp"]
            assert (pinv["nonzero_moving"], pinv["engaged_moving"]) == (dof, 0.0)
            assert pinv["within_bound"] == 0.0
            assert 1 <= lp["engaged_moving"]
            assert lp["nonzero_moving"] <= TASKS[family] + lp["engaged_moving"]
            assert all(0.0 <= laws[law]["reached"] <= 1.0 for law in laws)


def test_the_command_prints_a_report_its_table_and_figure_and_two_reports_merged(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    figure = tmp_path / "redundancy.png"
    argv = ["--robots", "snake12", "--goals", "1", "--workers", "1", "--time-limit", "0.2"]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    report = json.loads(out)
    assert report["goals"] == 1 and report["time_limit_s"] == 0.2
    assert list(report["robots"]) == ["snake12"]
    assert "snake12" in err and "nonzero moving" in err  # the table, on stderr
    little = json.loads(out)
    little["robots"] = {"little_john": {**report["robots"]["snake12"], "dof": 8}}
    paths = [tmp_path / "a.json", tmp_path / "b.json"]
    paths[0].write_text(out)
    paths[1].write_text(json.dumps(little))
    assert main(["--from", *map(str, paths), "--figure", str(figure)]) == 0
    merged = json.loads(capsys.readouterr().out)
    assert list(merged["robots"]) == ["snake12", "little_john"]
    assert figure.read_bytes()[:4] == b"\x89PNG" and figure.stat().st_size < 100_000


@pytest.mark.parametrize(
    "argv",
    [
        ["--robots", "no_such_robot"],
        ["--goals", "0"],
        ["--time-limit", "-1"],
        ["--families", "joint"],
    ],
)
def test_bad_arguments_are_one_line_and_exit_2(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.strip().splitlines()) == 1 and "Traceback" not in err
