"""The scripted publisher (components.scripted_publisher) in this process on a real router: the
state of its parameters, and its goal, a position, a pose turned ``goal_yaw`` about the world z
axis, or the whole ``goal_pose`` given."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from components.runtime import Node
from components.scripted_publisher import ScriptedPublisher
from messages import topics

if TYPE_CHECKING:
    from tests.components.conftest import System


def test_the_state_and_the_position_goal_of_its_parameters(system: System) -> None:
    states, goals = system.inbox(topics.ROBOT_STATE), system.inbox(topics.CONTROL_GOAL)
    with Node(system.profile, "talker", ScriptedPublisher.params) as node:
        node.params.set("rate_hz", 100.0)
        ScriptedPublisher(node)
        node.params.set("base_x", 0.5)
        node.params.set("q3", -0.2)
        node.start()
        state = states.wait_for(lambda s: s.base_pose[0] == 0.5, "at base_x")
        goal = goals.wait_for(lambda g: True, "any")
    assert state.arm_joints == (0.0, 0.0, -0.2, 0.0, 0.0) and state.valid
    assert state.joint_names == ("q1", "q2", "q3", "q4", "q5")
    assert (goal.task, goal.position) == ("position", (1.0, 0.0, 0.5))


def test_a_pose_goal_is_its_position_turned_goal_yaw_or_the_goal_pose_given(
    system: System,
) -> None:
    """A quarter turn about z at p = (1, 0, 0.5): r = (c, 0, 0, s), c = s = sqrt(2)/2, and the
    dual part p r / 2 = (-s/4, c/2, -s/2, c/4), worked by hand."""
    goals = system.inbox(topics.CONTROL_GOAL)
    c = s = math.sqrt(0.5)
    given = (0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.25)
    with Node(system.profile, "talker", ScriptedPublisher.params) as node:
        node.params.set("rate_hz", 100.0)
        ScriptedPublisher(node)
        node.params.set("goal_task", "pose")
        node.params.set("goal_yaw", math.pi / 2)
        node.start()
        turned = goals.wait_for(lambda g: g.task == "pose", "a pose")
        node.params.set("goal_pose", list(given))
        whole = goals.wait_for(lambda g: g.task == "pose" and g.pose[0] == 0.0, "the given pose")
    expected = (c, 0.0, 0.0, s, -s / 4, c / 2, -s / 2, c / 4)
    np.testing.assert_allclose(turned.pose, expected, atol=1e-12)
    assert whole.pose == given
