"""The shell every controller process shares: ``robot/state`` in, base and arm commands out.

A controller module only names its law (``wbc.lp_law``, ``wbc.cascade_law``...) and
declares its parameters; the mathematics stays in ``wbc``. Each ``robot/state`` is one
control step::

    u = law.step(q, task, dt, obstacles)          u = [x', y', phi', q1'..q5']
    base/command = wheel_speeds(unicycle(x', y', phi', phi))        (m/s, rad/s)
    arm/command  = u[3:]                                            (rad/s)

with ``dt`` the difference of consecutive state stamps, clamped to [1 ms, 0.2 s] (0.02 s
at the first step), and a ``control/diagnostics`` message saying what the law did.

The controller commands zero, and says why in the diagnostics' ``status`` and ``reason``,
whenever it cannot trust its output: the state is older than ``stale_timeout_s`` (by its
stamp, or because states stopped arriving: a 10 Hz timer checks), the state is not
``valid``, there is no goal, the law raises or returns a status other than ``optimal``,
or a command would not be finite (counted as ``non_finite_commands``).

Commands and diagnostics carry the stamp of the state they answer, so their age on
arrival measures the whole loop; zeros sent by the timer carry the current time.

Parameters whose names match a field of the law's parameter dataclass (``eta``,
``beta``...) are passed to the law; a goal's ``eta`` and ``beta`` override them while
that goal holds. ``robot`` is a robot description file (relative to the working
directory); empty means the profile's robot.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import yaml

from components.params import Param, ParamError
from components.pubsub import Input
from components.runtime import Component, Node
from messages import topics
from messages.base import ARM_JOINTS
from messages.commands import ArmCommand, BaseCommand
from messages.diagnostics import ControllerDiagnostics
from messages.goal import Goal
from messages.header import Header
from messages.obstacles import Obstacles
from messages.state import RobotState
from wbc.base_motion import unicycle, wheel_speeds
from wbc.drive_tasks import HeadingTask, PointTask
from wbc.gains import gain_specs
from wbc.law_output import Law, LawOutput
from wbc.obstacles import Circle
from wbc.robot import MobileManipulator
from wbc.task import MEASUREMENT_TOLERANCE, PoseTask, PositionTask, Task, same_task

STALE_CHECK_PERIOD_S = 0.1
"""How often the controller checks that states still arrive."""

FIRST_DT_S = 0.02
"""dt of the first step, before two state stamps exist."""

DT_MIN_S, DT_MAX_S = 1e-3, 0.2
"""dt is clamped to this range, whatever the stamps say."""


def robot_loads(path: object) -> None:
    """``ParamError`` unless ``path`` is empty (the profile's robot) or a robot that loads."""
    if path:
        load_robot(Path(str(path)).resolve())


def law_params(gains_type: type) -> tuple[Param, ...]:
    """A law's gains as run-time parameters, each with the bounds, choices and doc its
    dataclass declares (``wbc.gains``)."""
    return tuple(
        Param(spec.name, spec.type, spec.default, low=spec.low, high=spec.high,
              choices=spec.choices, doc=spec.doc)
        for spec in gain_specs(gains_type)
    )  # fmt: skip


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


class Hold(Exception):
    """A reason to command zero: a short ``status`` and a human ``reason``."""

    def __init__(self, status: str, reason: str, output: LawOutput | None = None) -> None:
        super().__init__(reason)
        self.status = status
        self.reason = reason
        self.output = output


def task_of(goal: Goal) -> Task:
    """The ``wbc`` task a goal asks for."""
    if goal.task == "pose":
        return PoseTask(np.array(goal.pose))
    if goal.task == "position":
        return PositionTask(np.array(goal.position))
    if goal.task == "point":
        return PointTask(np.array(goal.point), np.array(goal.arm), float(goal.lookahead))
    return HeadingTask(float(goal.heading), np.array(goal.arm), np.array(goal.point))


def goal_of(task: Task, header: Header) -> Goal:
    """The goal that asks for ``task`` (``task_of`` of it gives the task back)."""
    if isinstance(task, PoseTask):
        return Goal(header=header, task="pose", pose=tuple(task.pose.tolist()))
    if isinstance(task, PositionTask):
        return Goal(header=header, task="position", position=tuple(task.position.tolist()))
    if isinstance(task, PointTask):
        return Goal(header=header, task="point", point=tuple(task.point.tolist()),
                    arm=tuple(task.arm.tolist()), lookahead=task.lookahead)  # fmt: skip
    if isinstance(task, HeadingTask):
        return Goal(header=header, task="heading", heading=task.heading,
                    arm=tuple(task.arm.tolist()), point=tuple(task.position.tolist()))  # fmt: skip
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
        self.goal: Goal | None = None
        self.task: Task | None = None
        self.obstacles: tuple[Circle, ...] = ()
        self.robot_path = self._robot_path()
        self.robot = load_robot(self.robot_path)
        self._gains_cache: tuple[int, Goal | None, Any, dict[str, float]] | None = None
        self.gains = self.current_gains()[0]
        self.law = self.law_type(self.robot, self.gains)
        self._robot_version = node.params.version
        self._last_stamp_ns: int | None = None
        node.counters["non_finite_commands"] = 0
        node.counters["law_errors"] = 0
        self.state_input = node.subscribe(topics.ROBOT_STATE, self.on_state)
        node.subscribe(topics.CONTROL_GOAL, self.on_goal)
        node.subscribe(topics.WORLD_OBSTACLES, self.on_obstacles)
        node.timer(STALE_CHECK_PERIOD_S, self.check_inputs_arrive)

    def on_goal(self, goal: Goal) -> None:
        """Take a goal; a different task (another kind, or a goal moved by over
        ``MEASUREMENT_TOLERANCE``) resets the law. A goal the law refuses (ValueError,
        counted in ``errors.control/goal``) drops the current one: no goal, zero commands.
        The goal's ``eta`` and ``beta`` must lie in the bounds of the parameters they override,
        as for ``parsimony param set``."""
        try:
            for name in ("eta", "beta"):
                value = getattr(goal, name)
                if value is not None and name in self.node.params:
                    self.node.params.param(name).check(value)
            task = task_of(goal)
        except ValueError:
            self.goal = self.task = None
            raise
        if self.task is None or not same_task(self.task, task, MEASUREMENT_TOLERANCE):
            self.law.reset()
        self.goal, self.task = goal, task

    def on_obstacles(self, message: Obstacles) -> None:
        """Take the obstacles every following step avoids."""
        self.obstacles = tuple(Circle(c.x, c.y, c.radius) for c in message.circles)

    def on_state(self, state: RobotState) -> None:
        """One control step: publish the law's commands, or zeros and why."""
        stamp = state.header.stamp_ns
        dt = FIRST_DT_S if self._last_stamp_ns is None else (stamp - self._last_stamp_ns) / 1e9
        self._last_stamp_ns = stamp
        try:
            output = self.control(state, min(max(dt, DT_MIN_S), DT_MAX_S))
            self.publish(stamp, output, state.base_pose[2])
        except Hold as hold:
            self.publish_zero(stamp, hold.status, hold.reason, hold.output)

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
        self.publish_zero(self.node.clock.now_ns(), "stale", reason)

    def clock_stalled(self, stalled_s: float) -> None:
        """The simulated clock stopped: command zero and say why."""
        self.publish_zero(self.node.clock.now_ns(), "stale",
                          f"sim/clock has not moved for {stalled_s:.2f} s")  # fmt: skip

    def control(self, state: RobotState, dt: float) -> LawOutput:
        """The law's output for ``state``, or ``Hold`` saying why there is none."""
        age_s = (self.node.clock.now_ns() - state.header.stamp_ns) / 1e9
        timeout_s = self.node.params["stale_timeout_s"]
        if age_s > timeout_s:
            raise Hold("stale", f"robot/state is {age_s:.2f} s old (timeout {timeout_s} s)")
        if not state.valid:
            raise Hold("invalid state", "robot/state is not valid (the estimator has no fix)")
        if self.task is None:
            raise Hold("no goal", "no control/goal received yet")
        self.update_law()
        try:
            output = self.law.step(np.array(state.configuration()), self.task, dt, self.obstacles)
        except Exception as error:
            self.node.count("law_errors")
            self.node.warn("law_errors", f"{self.law_name} law failed: {error}")
            raise Hold("error", f"the {self.law_name} law raised: {error}") from error
        if not output.ok:
            raise Hold(output.status, f"the {self.law_name} law returned {output.status}", output)
        return output

    def wanted_gains(self) -> Any:
        """The law's parameters from the current values, the goal's ``eta``/``beta`` first."""
        fields = {field.name for field in dataclasses.fields(self.gains_type)}
        values = {name: self.node.params[name] for name in fields if name in self.node.params}
        if self.goal is not None:
            for name in ("eta", "beta"):
                override = getattr(self.goal, name)
                if override is not None and name in fields:
                    values[name] = override
        return self.gains_type(**values)

    def current_gains(self) -> tuple[Any, dict[str, float]]:
        """``wanted_gains()`` and its float fields (the diagnostics' ``parameters``), computed
        again only after a parameter or the goal changed."""
        version, goal = self.node.params.version, self.goal
        cached = self._gains_cache
        if cached is None or cached[0] != version or cached[1] is not goal:
            gains = self.wanted_gains()
            values = dataclasses.asdict(gains)
            floats = {name: v for name, v in values.items() if isinstance(v, float)}
            cached = self._gains_cache = (version, goal, gains, floats)
        return cached[2], cached[3]

    def update_law(self) -> None:
        """Reload the robot if its parameter changed; pass changed gains to the law.
        Both are looked at only after a parameter or the goal changed."""
        version = self.node.params.version
        if version != self._robot_version:
            try:
                path = self._robot_path()
                if path != self.robot_path:
                    self.robot, self.robot_path = load_robot(path), path
                    self.gains = self.current_gains()[0]
                    self.law = self.law_type(self.robot, self.gains)
            except ParamError as error:
                raise Hold("error", str(error)) from error
            self._robot_version = version
        gains = self.current_gains()[0]
        if gains is not self.gains:
            if gains != self.gains:
                self.law.set_params(gains)
            self.gains = gains

    def publish(self, stamp_ns: int, output: LawOutput, phi: float) -> None:
        """Publish the commands of ``output``, or zeros if one of them is not finite."""
        u = output.u
        if u.shape != (3 + ARM_JOINTS,):
            raise Hold("error", f"u has shape {u.shape}; the arm command takes {ARM_JOINTS} joints")
        if not np.all(np.isfinite(u)):
            self._non_finite(u)
        base = wheel_speeds(*unicycle(u[0], u[1], u[2], phi), self.robot.base)
        wheels = (base.forward, base.angular, base.left_wheel, base.right_wheel)
        if not all(math.isfinite(value) for value in wheels):
            self._non_finite(np.array(wheels))
        self._put_commands(stamp_ns, wheels, tuple(u[3:].tolist()))
        self._put_diagnostics(stamp_ns, "optimal", "", output)

    def publish_zero(
        self, stamp_ns: int, status: str, reason: str, output: LawOutput | None = None
    ) -> None:
        """Publish zero commands and diagnostics saying why."""
        self._put_commands(stamp_ns, (0.0, 0.0, 0.0, 0.0), (0.0,) * ARM_JOINTS)
        self._put_diagnostics(stamp_ns, status, reason, output)

    def _non_finite(self, values: np.ndarray) -> None:
        self.node.count("non_finite_commands")
        self.node.warn("non_finite_commands", f"{self.law_name} law gave {values}; zero sent")
        raise Hold("non-finite", f"the {self.law_name} law gave a non-finite command {values}")

    def _put_commands(
        self, stamp_ns: int, wheels: tuple[float, ...], joints: tuple[float, ...]
    ) -> None:
        forward, angular, left, right = wheels
        base, arm = self.base_command, self.arm_command
        base.put(
            BaseCommand(
                header=self.node.header("base", stamp_ns, base.next_seq),
                forward_velocity=forward,
                angular_velocity=angular,
                left_wheel=left,
                right_wheel=right,
            )
        )
        arm.put(
            ArmCommand(
                header=self.node.header("arm", stamp_ns, arm.next_seq), joint_velocities=joints
            )
        )

    def _put_diagnostics(
        self, stamp_ns: int, status: str, reason: str, output: LawOutput | None
    ) -> None:
        parameters = self.current_gains()[1]
        self.diagnostics.put(
            ControllerDiagnostics(
                header=self.node.header("world", stamp_ns, self.diagnostics.next_seq),
                law=self.law_name,
                status=status,
                reason=reason,
                objective=_finite_or_none(output.objective if output else None),
                nonzero=output.nonzero if output else 0,
                practical_nonzero=output.practical_nonzero if output else 0,
                active_constraints=output.active_constraints if output else (),
                solve_time_us=output.solve_time_s * 1e6 if output else 0.0,
                error_norm=_finite_or_none(output.error_norm if output else None),
                parameters=parameters,
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


def load_robot(path: Path) -> MobileManipulator:
    """The robot described at ``path``, or ``ParamError`` saying why it cannot be loaded."""
    try:
        return MobileManipulator.from_yaml(path)
    except (OSError, ValueError, yaml.YAMLError) as error:
        raise ParamError(f"robot: cannot load {path}: {error}") from error


def _finite_or_none(value: float | None) -> float | None:
    return value if value is not None and math.isfinite(value) else None
