"""Why the supervisor refuses a goal it passes on as it is (``components.direct_goal``)."""

from __future__ import annotations

import numpy as np

from components.direct_goal import direct_refusal
from messages.goal import Goal
from messages.header import Header
from profiles.deploy_files import ROBOT_FILE
from wbc.geometry.scenarios import HOME
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
HEADER = Header(stamp_ns=1, frame="world", seq=0, source="test")


def test_a_position_goal_is_refused_for_its_arm_its_distance_or_out_of_sight() -> None:
    q = np.array(HOME)
    near = Goal(header=HEADER, task="position", position=(1.0, 0.0, 0.3))
    assert direct_refusal(near, q, ROBOT, ()) == ""
    arm = near.model_copy(update={"arm": (0.0,) * (ROBOT.arm_dof + 1)})
    assert direct_refusal(arm, q, ROBOT, ()).startswith(
        f"the position goal's arm has {ROBOT.arm_dof + 1} joints, the robot's are {ROBOT.arm_dof}"
    )
    far = Goal(header=HEADER, task="position", position=(50.0, 0.0, 0.3))
    assert "farther than the 10 m a goal may lie" in direct_refusal(far, q, ROBOT, ())
    sight = ((1.0, 0.0, 0.5),)  # half-planes a x + b y <= c: here x <= 0.5 m
    assert "cannot see the base" in direct_refusal(near, q, ROBOT, sight)
    assert (
        direct_refusal(Goal(header=HEADER, task="pose", pose=(1.0,) + (0.0,) * 7), q, ROBOT, ())
        == ""
    )
