"""messages.goal: a goal's target fields are those of its task, its gains the controller's
unless given."""

from __future__ import annotations

import math
from typing import Any

import pytest
from pydantic import ValidationError

from messages import IDENTITY_POSE, Goal
from tests.messages.message_examples import HEADER, POSE_GOAL, QUARTER_TURN_SHIFTED


@pytest.mark.parametrize(
    ("fields", "complaint"),
    [
        ({"task": "pose"}, "a pose task needs a pose"),
        ({"task": "pose", "pose": QUARTER_TURN_SHIFTED, "position": (0, 0, 0)}, "no position"),
        ({"task": "position"}, "a position task needs a position"),
        ({"task": "position", "position": (0, 0, 0), "pose": IDENTITY_POSE}, "no pose"),
        ({"task": "orientation", "pose": IDENTITY_POSE}, "task"),
        ({"task": "point", "point": (0, 0), "lookahead": 0.1}, "a point task needs an arm"),
        ({"task": "heading", "heading": 1.0, "arm": (0, 0, 0, 0, 0)}, "needs a point"),
        (
            {
                "task": "point",
                "point": (0, 0),
                "arm": (0, 0, 0, 0, 0),
                "lookahead": 0.1,
                "heading": 0.0,
            },
            "a point task takes no heading",
        ),
        (
            {"task": "point", "point": (0, math.nan), "arm": (0, 0, 0, 0, 0), "lookahead": 0.1},
            "point",
        ),
        ({"task": "pose", "pose": IDENTITY_POSE, "eta": 0.0}, "eta"),
        ({"task": "pose", "pose": IDENTITY_POSE, "beta": -1.0}, "beta"),
    ],
)
def test_goal_target_must_match_task(fields: dict[str, Any], complaint: str) -> None:
    with pytest.raises(ValidationError, match=complaint):
        Goal(header=HEADER, **fields)


def test_goal_gains_default_to_the_controllers_own() -> None:
    goal = Goal(header=HEADER, task="position", position=(1.0, 2.0, 0.5))
    assert (goal.eta, goal.beta, goal.pose) == (None, None, None)
    assert POSE_GOAL.eta == 5.0
