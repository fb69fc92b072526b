"""The shell every controller process shares: ``robot/state`` in, base and arm commands out.

A controller module only names its law (``wbc.laws.lp_law``, ``wbc.laws.cascade_law``...) and
declares its parameters; the mathematics stays in ``wbc``. Each ``robot/state`` is one
control step (``components.control_step``, the same step ``parsimony rerun`` runs), with a
``control/diagnostics`` message saying what the law did and every gain in force.

The controller commands zero, and says why in the diagnostics' ``status`` and ``reason``,
whenever it cannot trust its output (``ControlStep.step``), and also while states stop
arriving (a 10 Hz timer checks); a law that raises is counted as ``law_errors``, a command
that would not be finite as ``non_finite_commands``, a goal it refuses as ``refused_goals``,
a state whose joints are not the robot description's as ``refused_states`` (the names
expected logged).

Commands and diagnostics carry the stamp of the state they answer, so their age on
arrival measures the whole loop; zeros sent by the timer carry the current time.

Parameters whose names match a field of the law's parameter dataclass (``eta``,
``beta``...) are passed to the law; a goal's ``eta`` and ``beta`` override them while
that goal holds. ``robot`` is a robot description file (relative to the working
directory); empty means the profile's robot.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar

from components.control_step import (
    REFUSED_STATE,
    STOPPED,
    TELEOP,
    TELEOP_TIMEOUT_S,
    ControlStep,
    Step,
    gain_values,
    gains_of,
    task_of,
    teleop_step,
)
from components.params import Param, ParamError, load_robot
from components.pubsub import Input, Subscription
from components.runtime import Component, Node
from components.stop_latch import StopLatch, stop_text
from messages import topics
from messages.commands import ArmCommand, BaseCommand
from messages.diagnostics import ControllerDiagnostics
from messages.goal import Goal
from messages.header import Header
from messages.obstacles import Obstacles, obstacles_of
from messages.state import RobotState
from messages.teleop import TeleopCommand
from wbc.laws.gains import gain_specs
from wbc.laws.law_output import Law
from wbc.planning.drive_tasks import HeadingTask, PointTask
from wbc.robot import MobileManipulator
from wbc.task import MEASUREMENT_TOLERANCE, PoseTask, PositionTask, Task, same_task

STALE_CHECK_PERIOD_S = 0.1
"""How often the controller checks that states still arrive."""
STEP_COUNTERS = {
    "error": "law_errors",
    "non-finite": "non_finite_commands",
    REFUSED_STATE: "refused_states",
}
"""The counter of each step status that is counted and logged (zero sent)."""


def robot_loads(path: object) -> None:
    """``ParamError`` unless ``path`` is empty (the profile's robot) or a robot that loads."""
    if path:
        load_robot(Path(str(path)).resolve())


def law_params(gains_type: type) -> tuple[Param, ...]:
    """A law's gains as run-time parameters, as its dataclass declares them (``wbc.laws.gains``)."""
    return tuple(Param.of(spec) for spec in gain_specs(gains_type))


CONTROLLER_PARAMS = (
    Param("stale_timeout_s", float, 0.5, low=0.01, high=10.0, doc="command zero after this, s"),
    Param(
        "robot",
        str,
        "",
        doc="robot description (YAML); empty: the profile's robot",
        can_take=robot_loads,
    ),
)
"""The parameters of every controller, after those of its law."""


def goal_of(task: Task, header: Header) -> Goal:
    """The goal that asks for ``task`` (``task_of`` of it gives the task back)."""
    if isinstance(task, PoseTask):
        return Goal(header=header, task="pose", pose=tuple(task.pose.tolist()))
    if isinstance(task, PositionTask):
        return Goal(header=header, task="position", position=tuple(task.position.tolist()))
    if isinstance(task, PointTask):
        return Goal(
            header=header,
            task="point",
            point=tuple(task.point.tolist()),
            arm=tuple(task.arm.tolist()),
            lookahead=task.lookahead,
        )
    if isinstance(task, HeadingTask):
        return Goal(
            header=header,
            task="heading",
            heading=task.heading,
            arm=tuple(task.arm.tolist()),
            point=tuple(task.position.tolist()),
        )
    raise TypeError(f"no goal asks for a {type(task).__name__}")


class Controller(Component):
    """A control law as a process; subclasses set ``law_name``, ``law_type``, ``gains_type``
    and ``params`` (the law's parameters, then ``CONTROLLER_PARAMS``)."""

    law_name: ClassVar[str]
    law_type: ClassVar[Callable[[MobileManipulator, Any], Law]]
    gains_type: ClassVar[type]
    reads = (Input(topics.ROBOT_STATE), Input(topics.CONTROL_GOAL), Input(topics.WORLD_OBSTACLES))
    writes = (topics.BASE_COMMAND, topics.ARM_COMMAND, topics.CONTROL_DIAGNOSTICS)

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        self.base_command = node.publisher(topics.BASE_COMMAND)
        self.arm_command = node.publisher(topics.ARM_COMMAND)
        self.diagnostics = node.publisher(topics.CONTROL_DIAGNOSTICS)
        self.robot_path = self._robot_path()
        gains = gains_of(self.gains_type, node.params, None)
        self.stepper = ControlStep(self.law_name, self.law_type, load_robot(self.robot_path), gains)
        self._seen = (node.params.version, None)  # the parameters and goal the gains are of
        node.counters["non_finite_commands"] = 0
        node.counters["law_errors"] = 0
        node.counters["refused_goals"] = 0
        node.counters["refused_obstacles"] = 0
        node.counters["refused_states"] = 0
        self.latch = StopLatch(node)
        self.state_input = node.subscribe(topics.ROBOT_STATE, self.on_state)
        node.subscribe(topics.CONTROL_GOAL, self.on_goal)
        node.subscribe(topics.WORLD_OBSTACLES, self.on_obstacles)
        # A tool's input (`parsimony teleop`), not the graph's: no launch warns that no
        # component writes it.
        self.teleop = Subscription(node, topics.TELEOP_COMMAND, self.on_teleop)
        self.teleoperated = False
        """A hand commands the robot: the goal yields until a new one."""
        node.timer(STALE_CHECK_PERIOD_S, self.check_inputs_arrive)

    @property
    def robot(self) -> MobileManipulator:
        return self.stepper.robot

    def on_goal(self, goal: Goal) -> None:
        """Take a goal (``ControlStep.take_goal``). A goal the law refuses (counted in
        ``refused_goals``, one line logged) drops the current one: zero commands, and the
        diagnostics say why (``goal refused``) until the next goal. The goal's ``eta`` and
        ``beta`` must lie in the bounds of the gains they override, the bounds of their
        parameters too (``parsimony param set``). While teleoperated, the goal held is ignored
        (measured again or passed on again); another ends the teleoperation."""
        if self.teleoperated and self._holds(goal):
            return
        self.teleoperated = False
        try:
            self.stepper.take_goal(goal)
        except ValueError:
            self.node.count("refused_goals")
            self.node.warn(
                "refused_goals", f"{self.stepper.refusal}; zero sent until the next goal"
            )

    def _holds(self, goal: Goal) -> bool:
        """Whether ``goal`` asks what the goal held asks."""
        try:
            task = task_of(goal)
        except ValueError:
            return False
        held = self.stepper.task
        return held is not None and same_task(held, task, MEASUREMENT_TOLERANCE)

    def on_teleop(self, _hand: TeleopCommand) -> None:
        """A hand takes the robot: the goal yields (``hand_step`` on each state)."""
        if not self.teleoperated:
            self.teleoperated = True
            self.node.warn("teleop", f"{self.node.name}: teleoperated; the goal yields")

    def on_obstacles(self, message: Obstacles) -> None:
        """Take the obstacles every following step avoids; a message with a solid the law
        cannot take (``wbc.geometry.obstacles3d``: a cylinder of radius 1e300) is refused in one
        line (``refused_obstacles``), and the last obstacles kept."""
        try:
            obstacles = obstacles_of(message)
        except ValueError as error:
            self.node.count("refused_obstacles")
            self.node.warn(
                "refused_obstacles", f"world/obstacles refused: {error}; the last obstacles kept"
            )
            return
        self.stepper.take_obstacles(obstacles)

    def on_state(self, state: RobotState) -> None:
        """One control step: publish its commands and diagnostics; zero while the namespace is
        stopped (``components.stop_latch``), the goal kept for after the release."""
        if self.latch.stopped:
            self.stepper.last_stamp_ns = state.header.stamp_ns
            stamp = state.header.stamp_ns
            self.publish(self.stepper.zero(stamp, STOPPED, stop_text(self.latch.state)))
            return
        if self.teleoperated:
            self.stepper.last_stamp_ns = state.header.stamp_ns
            self.publish(self.hand_step(state))
            return
        try:
            self.update_law()
        except ParamError as error:
            self.stepper.last_stamp_ns = state.header.stamp_ns
            self.publish(self.stepper.zero(state.header.stamp_ns, "error", str(error)))
            return
        step = self.stepper.step(
            state, self.node.clock.now_ns(), self.node.params["stale_timeout_s"]
        )
        counter = STEP_COUNTERS.get(step.status)
        if counter is not None:
            self.node.count(counter)
            self.node.warn(counter, f"{step.reason}; zero sent")
        self.publish(step)

    def hand_step(self, state: RobotState) -> Step:
        """The teleoperated step: the hand's command, zero once it is older than the dead-man
        timeout (``TELEOP_TIMEOUT_S``)."""
        hand, age_s = self.teleop.latest, self.teleop.age_s()
        if hand is None or age_s > TELEOP_TIMEOUT_S:
            reason = f"no teleop/command for {age_s:.2f} s (dead-man {TELEOP_TIMEOUT_S} s)"
            return self.stepper.zero(state.header.stamp_ns, TELEOP, reason)
        self.stepper.law.stopped()
        return teleop_step(self.robot, state, hand)

    def check_inputs_arrive(self) -> None:
        """Timer: command zero while no state has arrived for ``stale_timeout_s``."""
        age_s, timeout_s = self.state_input.age_s(), self.node.params["stale_timeout_s"]
        if age_s <= timeout_s:
            return
        reason = (
            "no robot/state received yet"
            if math.isinf(age_s)
            else f"no robot/state for {age_s:.2f} s (timeout {timeout_s} s)"
        )
        self.publish(self.stepper.zero(self.node.clock.now_ns(), "stale", reason))

    def clock_stalled(self, stalled_s: float) -> None:
        """The simulated clock stopped: command zero and say why."""
        self.publish(
            self.stepper.zero(
                self.node.clock.now_ns(), "stale", f"sim/clock has not moved for {stalled_s:.2f} s"
            )
        )

    def update_law(self) -> None:
        """After a parameter or the goal changed: reload the robot if its parameter changed,
        and pass the gains (the goal's ``eta``/``beta`` over the parameters) to the law."""
        seen = (self.node.params.version, self.stepper.goal)
        if seen[0] == self._seen[0] and seen[1] is self._seen[1]:
            return
        path = self._robot_path()
        if path != self.robot_path:
            robot = load_robot(path)
            self.robot_path = path
            self.stepper.use(robot)
        self.stepper.set_gains(gains_of(self.gains_type, self.node.params, self.stepper.goal))
        self._seen = seen

    def publish(self, step: Step) -> None:
        """The commands and the diagnostics of ``step``."""
        forward, angular, left, right = step.wheels
        base, arm = self.base_command, self.arm_command
        base.put(
            BaseCommand(
                header=self.node.header("base", step.stamp_ns, base.next_seq),
                forward_velocity=forward,
                angular_velocity=angular,
                left_wheel=left,
                right_wheel=right,
                lateral_velocity=step.lateral,
            )
        )
        arm.put(
            ArmCommand(
                header=self.node.header("arm", step.stamp_ns, arm.next_seq),
                joint_velocities=step.joints,
                joint_names=self.robot.joint_names,
            )
        )
        self.diagnostics.put(
            diagnostics_of(
                step,
                self.law_name,
                self.stepper.gains,
                self.node.header("world", step.stamp_ns, self.diagnostics.next_seq),
            )
        )

    def _robot_path(self) -> Path:
        """The ``robot`` parameter, or the profile's robot when it is empty."""
        path = str(self.node.params["robot"])
        if path:
            return Path(path).resolve()
        if self.node.profile.robot is None:
            raise ParamError("robot: no robot description; set it or the profile's `robot`")
        return self.node.profile.robot


def diagnostics_of(step: Step, law: str, gains: Any, header: Header) -> ControllerDiagnostics:
    """What ``step`` did, as the diagnostics say it, with every gain in force."""
    output = step.output
    return ControllerDiagnostics(
        header=header,
        law=law,
        status=step.status,
        reason=step.reason,
        objective=_finite_or_none(output.objective if output else None),
        nonzero=output.nonzero if output else 0,
        practical_nonzero=output.practical_nonzero if output else 0,
        active_constraints=output.active_constraints if output else (),
        solve_time_us=output.solve_time_s * 1e6 if output else 0.0,
        error_norm=_finite_or_none(output.error_norm if output else None),
        parameters=gain_values(gains),
    )


def _finite_or_none(value: float | None) -> float | None:
    return value if value is not None and math.isfinite(value) else None
