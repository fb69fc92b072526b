"""A kinematic sweep run on the local pool and handed back as attempts: keyed by family,
task, seed and law label, in goal order, each the attempt the same goal gives in this process;
a run failed twice is a RuntimeError naming it."""

from __future__ import annotations

import pytest

from profiles.deploy_files import ROBOT_FILE
from studies.goal_families import FAMILIES, goals
from studies.goal_sets import STUDY_LAWS, attempt
from studies.study.attempts import sweep_attempts
from studies.study.schema import Study
from wbc.robot import MobileManipulator

SEED = 2


def tiny(**changes: object) -> Study:
    return Study.model_validate(
        {
            "name": "tiny",
            "robots": [str(ROBOT_FILE)],
            "families": ["ahead"],
            "goals": 2,
            "seeds": [SEED],
            "laws": [{"law": "lp"}],
        }
        | changes
    )


def test_each_goals_attempt_is_the_one_this_process_makes_in_goal_order() -> None:
    found = sweep_attempts(tiny(), workers=2)
    assert list(found) == [("ahead", "pose", SEED, "lp")]
    robot = MobileManipulator.from_yaml(ROBOT_FILE)
    here = [
        attempt(STUDY_LAWS["lp"](robot), robot, start, goal)
        for start, goal in goals(FAMILIES["ahead"], 2, robot, SEED)
    ]
    pooled = found[("ahead", "pose", SEED, "lp")]
    assert [(a.converged, a.steps, a.nonzero) for a in pooled] == [
        (a.converged, a.steps, a.nonzero) for a in here
    ]


def test_a_run_that_failed_twice_is_a_runtime_error_naming_it() -> None:
    with pytest.raises(RuntimeError, match=r"^run .+ failed: hung: no answer within"):
        sweep_attempts(tiny(goals=1, time_limit_s=0.001), workers=1)
