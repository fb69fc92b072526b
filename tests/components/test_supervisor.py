"""The supervisor process between the operator's goal and the controller's (real Zenoh)."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import pytest
from conftest import DEADLINE_S, DEPLOY, System

from components.controller import goal_of, task_of
from messages import codec, topics
from messages.goal import Goal
from messages.header import Header
from messages.state import RobotState
from wbc.drive_tasks import HeadingTask, PointTask
from wbc.planar import planar_pose
from wbc.robot import MobileManipulator
from wbc.scenarios import HOME, REACH_GOAL
from wbc.task import PoseTask, PositionTask, same_task

MODEL = MobileManipulator.from_yaml(DEPLOY / "robots" / "little_john.yaml")

PROFILE = """
namespace: supervised
zenoh: {router: ["tcp/127.0.0.1:7447"]}
robot: robots/little_john.yaml
components:
  - {name: supervisor, module: supervisor, role: controller}
"""


class Operator:
    """Goals and states to the supervisor; its goals and statuses back."""

    def __init__(self, system: System) -> None:
        namespace = system.profile.namespace
        self.robot = MobileManipulator.from_yaml(system.profile.robot)
        self.request = system.router.declare_publisher(topics.GOAL_REQUEST.key(namespace))
        self.state = system.router.declare_publisher(topics.ROBOT_STATE.key(namespace))
        self.goals = system.inbox(topics.CONTROL_GOAL)
        self.statuses = system.inbox(topics.SUPERVISOR_STATUS)
        deadline = time.monotonic() + DEADLINE_S
        while not (self.request.matching_status.matching and self.state.matching_status.matching):
            assert time.monotonic() < deadline, "the supervisor did not subscribe in time"
            time.sleep(0.005)

    def ask(self, pose: np.ndarray) -> None:
        header = Header(stamp_ns=time.time_ns(), frame="world", seq=0, source="test")
        self.request.put(codec.encode(Goal(header=header, task="pose", pose=tuple(pose))))

    def send_state(self, q: np.ndarray) -> None:
        header = Header(stamp_ns=time.time_ns(), frame="world", seq=0, source="test")
        x = tuple(self.robot.fkm(q))
        state = RobotState(header=header, base_pose=tuple(q[:3]), arm_joints=tuple(q[3:]),
                           end_effector=x, valid=True, age_s=0.0)  # fmt: skip
        self.state.put(codec.encode(state))


def supervised(deployed: Callable[[str], System]) -> Operator:
    system = deployed(PROFILE)
    system.start("supervisor")
    return Operator(system)


def test_a_goal_behind_the_robot_becomes_a_drive_leg_for_the_controller(
    deployed: Callable[[str], System],
) -> None:
    operator = supervised(deployed)
    behind = operator.robot.fkm(np.concatenate(([-0.8, 0.2, 3.0], REACH_GOAL[3:])))
    operator.ask(behind)
    operator.send_state(HOME)
    goal = operator.goals.wait_for(lambda g: True, "the controller's goal")
    status = operator.statuses.wait_for(lambda s: True, "a status")
    assert goal.task == "point" and goal.arm is not None and goal.lookahead is not None
    assert status.phase == "drive" and status.plans == 1 and status.candidate == 1
    assert status.candidate_base is not None and status.candidate_base[0] < -0.3
    assert status.planning_ms is not None and status.planning_ms > 0.0


def test_an_unreachable_goal_is_reported_and_the_robot_is_held_where_it_stands(
    deployed: Callable[[str], System],
) -> None:
    operator = supervised(deployed)
    operator.ask(planar_pose(0.5, 0.0, 0.0, 2.0))  # 2 m above the floor
    for _ in range(2):
        operator.send_state(HOME)
    status = operator.statuses.wait_for(lambda s: s.phase == "unreachable", "unreachable")
    assert "no whole-body configuration" in status.reason
    hold = operator.goals.wait_for(lambda g: True, "the controller's goal")
    assert hold.task == "point"
    np.testing.assert_allclose(hold.arm, HOME[3:])
    np.testing.assert_allclose(hold.point, HOME[:2] + [hold.lookahead, 0.0])


@pytest.mark.parametrize("task", [
    PoseTask(MODEL.fkm(REACH_GOAL)),
    PositionTask(np.array([0.5, -0.2, 0.3])),
    PointTask(np.array([0.4, -0.2]), np.array([0.0, -0.3, 0.2, 0.0, 0.4]), 0.03),
    HeadingTask(-2.5, np.array([0.0, -0.3, 0.2, 0.0, 0.4]), np.array([0.3, 0.1])),
])  # fmt: skip
def test_the_goal_of_every_task_kind_asks_for_that_task(task) -> None:
    header = Header(stamp_ns=1, frame="world", seq=0, source="test")
    back = task_of(codec.decode(codec.encode(goal_of(task, header)), Goal))
    assert type(back) is type(task) and same_task(back, task)
