"""The supervisor process with the test as its operator: goals and states to it, its goals and
statuses back (for the supervisor's tests and teleoperation's)."""

from __future__ import annotations

import time
from collections.abc import Callable

import msgpack
import numpy as np

from components.controller import goal_of
from messages import codec, topics
from messages.goal import Goal
from messages.header import Header
from messages.state import RobotState
from messages.supervisor import SupervisorStatus
from profiles.deploy_files import ROBOT_FILE
from tests.components.conftest import DEADLINE_S, System
from wbc import dq
from wbc.geometry.scenarios import HOME
from wbc.planning.drive_tasks import HeadingTask, PointTask, offset_point
from wbc.robot import MobileManipulator
from wbc.task import PositionTask

MODEL = MobileManipulator.from_yaml(ROBOT_FILE)

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
        self.system = system
        self.request = system.router.declare_publisher(topics.GOAL_REQUEST.key(namespace))
        self.state = system.router.declare_publisher(topics.ROBOT_STATE.key(namespace))
        self.obstacles = system.router.declare_publisher(topics.WORLD_OBSTACLES.key(namespace))
        self.goals = system.inbox(topics.CONTROL_GOAL)
        self.statuses = system.inbox(topics.SUPERVISOR_STATUS)
        deadline = time.monotonic() + DEADLINE_S
        while not (self.request.matching_status.matching and self.state.matching_status.matching):
            assert time.monotonic() < deadline, "the supervisor did not subscribe in time"
            time.sleep(0.005)

    def ask(self, pose: np.ndarray) -> int:
        """A pose goal; its stamp, which the statuses once it is taken carry."""
        return self.send_goal(Goal(header=header(), task="pose", pose=tuple(pose)))

    def ask_raw(self, fields: dict) -> None:
        """A request as its bytes, whatever its fields hold (a NaN, a pose of norm 2...)."""
        fields = {"header": header().model_dump(), "task": "pose", **fields}
        self.request.put(msgpack.packb([codec.FORMAT_TAG, "Goal", fields], use_bin_type=True))

    def send_state(self, q: np.ndarray, valid: bool = True, age_s: float = 0.0) -> int:
        """A state at q; its stamp, which the supervisor's status answering it carries."""
        header = Header(stamp_ns=time.time_ns(), frame="world", seq=0, source="test")
        x = tuple(self.robot.fkm(q))
        state = RobotState(
            header=header,
            base_pose=tuple(q[:3]),
            arm_joints=tuple(q[3:]),
            end_effector=x,
            valid=valid,
            age_s=age_s,
        )
        self.state.put(codec.encode(state))
        return header.stamp_ns

    def send_goal(self, goal: Goal) -> int:
        """``goal``; its stamp, which the statuses once it is taken carry."""
        self.request.put(codec.encode(goal))
        return goal.header.stamp_ns

    def status_answering(self, q: np.ndarray, what: str, **state: object) -> SupervisorStatus:
        """A state at q, and the status the supervisor published for it (stamped with it): not
        one published before it (a tick's, an earlier state's still on its way)."""
        stamp = self.send_state(q, **state)
        return self.statuses.wait_for(lambda s: s.header.stamp_ns == stamp, what)

    def answer_to(
        self, goal_stamp: int, q: np.ndarray, what: str, **state: object
    ) -> SupervisorStatus:
        """States at q until one is answered with the goal of ``goal_stamp`` taken (a goal and
        a state travel apart): the status answering that state."""
        deadline = time.monotonic() + DEADLINE_S
        while (status := self.status_answering(q, what, **state)).request_stamp_ns != goal_stamp:
            assert time.monotonic() < deadline, f"the goal was never taken ({what})"
        return status


def header() -> Header:
    return Header(stamp_ns=time.time_ns(), frame="world", seq=0, source="test")


def supervised(deployed: Callable[[str], System], profile: str = PROFILE) -> Operator:
    """The supervisor process and the test as its operator; states go out until its first
    (idle) status comes back, so that its session knows the test's subscribers."""
    system = deployed(profile)
    system.start("supervisor")
    operator = Operator(system)
    deadline = time.monotonic() + DEADLINE_S
    while not operator.statuses.messages:
        assert time.monotonic() < deadline, "no status from the supervisor"
        operator.send_state(HOME)
        time.sleep(0.01)
    return operator


def met_at(q: np.ndarray) -> dict[str, Goal]:
    """A goal of each kind but the pose whose task is met at configuration q."""
    d = 0.03
    position = PositionTask(dq.translation(MODEL.fkm(q))[1:])
    point = PointTask(offset_point(q, d), q[3:], d)
    heading = HeadingTask(float(q[2]), q[3:], q[:2])
    return {task.__class__.__name__: goal_of(task, header()) for task in (position, point, heading)}
