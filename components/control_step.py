"""One control step: a pure function of the law, the state, the goal, the obstacles and the
clock, shared by the controller process (``components.controller``) and ``parsimony rerun``::

    u = law.step(q, task, dt, obstacles)          u = [x', y', phi', q1'..qn']
    base/command = wheel_speeds(unicycle(x', y', phi', phi))        (m/s, rad/s)
    arm/command  = u[3:]                        (rad/s, m/s; the description's joint_names)

for a differential base; an omnidirectional base is commanded (x', y') turned into its own
frame (forward, lateral) and phi', a fixed base nothing (``base_command``).

with ``dt`` the difference of consecutive state stamps, clamped to [1 ms, 0.2 s] (0.02 s at
the first step). The step commands zero, and says why (``status``, ``reason``), whenever its
output cannot be trusted: the state is older than the stale timeout, it is not ``valid``,
its joints are not the robot's (``REFUSED_STATE``), there is no goal (none yet, or the last
one was refused), the law raises or returns a status
other than ``optimal``, or a command would not be finite.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from components.joint_check import mismatch
from messages.goal import Goal
from messages.state import RobotState
from messages.teleop import TeleopCommand
from wbc.base_motion import unicycle, wheel_speeds
from wbc.geometry.obstacles import Obstacle
from wbc.laws.gains import gain_specs
from wbc.laws.law_output import Law, LawOutput
from wbc.planning.drive_tasks import HeadingTask, PointTask
from wbc.robot import BaseDescription, MobileManipulator
from wbc.task import MEASUREMENT_TOLERANCE, PoseTask, PositionTask, Task, same_task

FIRST_DT_S = 0.02
"""dt of the first step, before two state stamps exist."""
DT_MIN_S, DT_MAX_S = 1e-3, 0.2
"""dt is clamped to this range, whatever the stamps say."""
GOAL_OVERRIDES = ("eta", "beta")
"""The gains a goal may set while it holds."""
ZERO_WHEELS = (0.0, 0.0, 0.0, 0.0)
REFUSED_STATE = "refused state"
"""The status of a step on a state whose joints are not the robot's (zero sent)."""
TELEOP = "teleop"
"""The status of a step commanded by hand (``teleop_step``), or of its zero (why said)."""
TELEOP_TIMEOUT_S = 0.5
"""The dead-man timeout: a hand's command older than this commands zero."""
STOPPED = "stopped"
"""The status of a step while the namespace is stopped (``components.stop_latch``; zero sent)."""


def base_command(
    u_b: np.ndarray, phi: float, base: BaseDescription
) -> tuple[tuple[float, float, float, float], float]:
    """What the base is told for u_b = [x', y', phi'] at heading ``phi``: (forward, angular,
    left wheel, right wheel) and the lateral speed. A differential base: v and omega of the
    unicycle (5.11), as wheel speeds under their limit; an omnidirectional one: (x', y') in its
    own frame, no wheels; a fixed one: nothing. NaN where a speed would not be finite."""
    if base.kind == "fixed":
        return ZERO_WHEELS, 0.0
    if base.kind == "omnidirectional":
        c, s = math.cos(phi), math.sin(phi)
        forward, lateral = c * u_b[0] + s * u_b[1], -s * u_b[0] + c * u_b[1]
        return (float(forward), float(u_b[2]), 0.0, 0.0), float(lateral)
    speeds, wheels = unicycle(u_b[0], u_b[1], u_b[2], phi), (math.nan,) * 4
    if all(math.isfinite(v) for v in speeds):  # v may overflow where u does not
        velocity = wheel_speeds(*speeds, base)
        wheels = (velocity.forward, velocity.angular, velocity.left_wheel, velocity.right_wheel)
    return wheels, 0.0


def teleop_step(robot: MobileManipulator, state: RobotState, hand: TeleopCommand) -> Step:
    """The commands of a hand's ``hand`` at ``state`` (stamped with its stamp): the base's
    forward speed and turn as u_b in F0, scaled down as a whole into the base's velocity
    limits; the joint it names at its velocity clamped to its limit, still where it would
    leave its joint limits; every other joint still."""
    stamp, dof = state.header.stamp_ns, robot.arm_dof
    why = mismatch(state.joint_names, robot.joint_names)
    if why:
        return Step.zero(stamp, dof, REFUSED_STATE, f"robot/state refused: it has {why}")
    if hand.joint and hand.joint not in robot.joint_names:
        names = ", ".join(robot.joint_names)
        return Step.zero(stamp, dof, TELEOP, f"no joint {hand.joint!r}: the robot's are {names}")
    phi = state.base_pose[2]
    u_b = np.array([hand.forward * math.cos(phi), hand.forward * math.sin(phi), hand.turn])
    limits = robot.velocity_max[:3]
    over = max(
        (abs(u) / m if m > 0 else math.inf for u, m in zip(u_b, limits, strict=True) if u),
        default=0.0,
    )
    u_b = u_b / max(1.0, over) if over < math.inf else np.zeros(3)
    wheels, lateral = base_command(u_b, phi, robot.base)
    joints = [0.0] * dof
    if hand.joint:
        index = robot.joint_names.index(hand.joint)
        limit = robot.velocity_max[3 + index]
        velocity = max(-limit, min(limit, hand.joint_velocity))
        q = state.arm_joints[index]
        leaving = (velocity > 0 and q >= robot.q_max[3 + index]) or (
            velocity < 0 and q <= robot.q_min[3 + index]
        )
        joints[index] = 0.0 if leaving else float(velocity)
    return Step(stamp, wheels, tuple(joints), TELEOP, "", None, lateral)


def task_of(goal: Goal) -> Task:
    """The ``wbc`` task a goal asks for."""
    if goal.task == "pose":
        return PoseTask(np.array(goal.pose))
    if goal.task == "position":
        return PositionTask(np.array(goal.position))
    if goal.task == "point":
        return PointTask(np.array(goal.point), np.array(goal.arm), float(goal.lookahead))
    return HeadingTask(float(goal.heading), np.array(goal.arm), np.array(goal.point))


@dataclass(frozen=True)
class Step:
    """What one step commands: the base's (forward, angular, left wheel, right wheel) and the
    arm's joint speeds, the outcome (``optimal`` or why zero was sent), the law's output
    when there is one and an omnidirectional base's ``lateral`` speed (m/s)."""

    stamp_ns: int
    wheels: tuple[float, float, float, float]
    joints: tuple[float, ...]
    status: str
    reason: str = ""
    output: LawOutput | None = None
    lateral: float = 0.0

    @classmethod
    def zero(
        cls,
        stamp_ns: int,
        arm_dof: int,
        status: str,
        reason: str,
        output: LawOutput | None = None,
    ) -> Step:
        """Zero commands to the base and to the ``arm_dof`` joints, and why."""
        return cls(stamp_ns, ZERO_WHEELS, (0.0,) * arm_dof, status, reason, output)


class ControlStep:
    """A law stepped on states: the task of the last goal (a different task resets the law),
    the last obstacles, the last state's stamp (for dt) and the gains in force."""

    def __init__(
        self,
        name: str,
        law_type: Callable[[MobileManipulator, Any], Law],
        robot: MobileManipulator,
        gains: Any,
    ) -> None:
        self.name, self.law_type, self.robot = name, law_type, robot
        self.gains = gains
        self.law = law_type(robot, gains)
        self.goal: Goal | None = None
        self.task: Task | None = None
        self.obstacles: tuple[Obstacle, ...] = ()
        self.last_stamp_ns: int | None = None
        self.refusal = ""
        """Why the last goal was refused, while no goal holds."""

    def take_goal(self, goal: Goal) -> None:
        """Follow ``goal``; a goal the law cannot take (``ValueError``, naming the field and
        what it must be: its ``eta`` or ``beta`` outside the bounds the gains declare, an
        ``arm`` of another size than the robot's, or a task the law refuses) drops the current
        one, and the steps until the next goal say
        why (status ``goal refused``)."""
        try:
            declared = {spec.name: spec for spec in gain_specs(type(self.gains))}
            for name in GOAL_OVERRIDES:
                value = getattr(goal, name)
                if value is not None and name in declared:
                    declared[name].check(value)
            if goal.arm is not None and len(goal.arm) != self.robot.arm_dof:
                names = ", ".join(self.robot.joint_names)
                raise ValueError(f"arm: {len(goal.arm)} joints, the robot's are {names}")
            task = task_of(goal)
        except ValueError as error:
            self.goal = self.task = None
            self.refusal = f"control/goal refused: {error}"
            raise
        self.refusal = ""
        if self.task is None or not same_task(self.task, task, MEASUREMENT_TOLERANCE):
            self.law.reset()
        self.goal, self.task = goal, task

    def take_obstacles(self, obstacles: tuple[Obstacle, ...]) -> None:
        """The circles and solids every following step avoids."""
        self.obstacles = obstacles

    def use(self, robot: MobileManipulator) -> None:
        """Control ``robot`` from now on (a new law of the gains in force)."""
        self.robot, self.law = robot, self.law_type(robot, self.gains)

    def set_gains(self, gains: Any) -> None:
        """The gains of the following steps (the law is told only when they differ)."""
        if gains != self.gains:
            self.law.set_params(gains)
        self.gains = gains

    def step(self, state: RobotState, now_ns: int, stale_timeout_s: float) -> Step:
        """The commands answering ``state`` at ``now_ns``, stamped with its stamp; where they
        are zero instead of the law's u, the law is told (``Law.stopped``)."""
        step = self._commands(state, now_ns, stale_timeout_s)
        if step.status != "optimal":
            self.law.stopped()
        return step

    def zero(self, stamp_ns: int, status: str, reason: str) -> Step:
        """Zero commands stamped ``stamp_ns``, for ``status`` and ``reason``, sent without a
        step (no state, a stopped clock, a bad parameter); the law is told (``Law.stopped``)."""
        self.law.stopped()
        return self._halt(stamp_ns, status, reason)

    def _halt(
        self, stamp_ns: int, status: str, reason: str, output: LawOutput | None = None
    ) -> Step:
        """Zero commands to the base and to every joint of the robot, and why."""
        return Step.zero(stamp_ns, self.robot.arm_dof, status, reason, output)

    def _commands(self, state: RobotState, now_ns: int, stale_timeout_s: float) -> Step:
        stamp = state.header.stamp_ns
        dt = FIRST_DT_S if self.last_stamp_ns is None else (stamp - self.last_stamp_ns) / 1e9
        self.last_stamp_ns = stamp
        age_s = (now_ns - stamp) / 1e9
        if age_s > stale_timeout_s:
            return self._halt(
                stamp, "stale", f"robot/state is {age_s:.2f} s old (timeout {stale_timeout_s} s)"
            )
        why = mismatch(state.joint_names, self.robot.joint_names)
        if why:
            return self._halt(stamp, REFUSED_STATE, f"robot/state refused: it has {why}")
        if not state.valid:
            return self._halt(
                stamp, "invalid state", "robot/state is not valid (the estimator has no fix)"
            )
        if self.task is None and self.refusal:
            return self._halt(stamp, "goal refused", self.refusal)
        if self.task is None:
            return self._halt(stamp, "no goal", "no control/goal received yet")
        try:
            output = self.law.step(
                np.array(state.configuration()),
                self.task,
                min(max(dt, DT_MIN_S), DT_MAX_S),
                self.obstacles,
            )
        except Exception as error:  # noqa: BLE001 - any failure of the law holds the robot
            return self._halt(stamp, "error", f"the {self.name} law raised: {error}")
        if not output.ok:
            return self._halt(
                stamp, output.status, f"the {self.name} law returned {output.status}", output
            )
        u = output.u
        if u.shape != (3 + self.robot.arm_dof,):
            return self._halt(
                stamp,
                "error",
                f"u has shape {u.shape}; the arm command takes {self.robot.arm_dof} joints",
            )
        if not np.all(np.isfinite(u)):  # before any conversion, which would raise
            return self._halt(
                stamp,
                "non-finite",
                f"the {self.name} law reported optimal with a non-finite u {u} (a law error)",
            )
        wheels, lateral = base_command(u[:3], state.base_pose[2], self.robot.base)
        if not all(math.isfinite(w) for w in (*wheels, lateral)):
            return self._halt(
                stamp, "non-finite", f"the {self.name} law's u {u} gives non-finite base speeds"
            )
        return Step(stamp, wheels, tuple(u[3:].tolist()), "optimal", "", output, lateral)


def gains_of(gains_type: type, values: Mapping[str, Any], goal: Goal | None) -> Any:
    """The law's gains from ``values`` (the fields of ``gains_type`` they name), a goal's
    ``GOAL_OVERRIDES`` over them while it holds."""
    fields = {field.name for field in dataclasses.fields(gains_type)}
    chosen = {name: value for name, value in values.items() if name in fields}
    if goal is not None:
        for name in GOAL_OVERRIDES:
            override = getattr(goal, name)
            if override is not None and name in fields:
                chosen[name] = override
    return gains_type(**chosen)


def gain_values(gains: Any) -> dict[str, float | bool | str]:
    """Every gain in force by name: what the diagnostics carry, so a recording says which
    gains each step ran with (``parsimony rerun`` takes them back with ``gains_of``)."""
    return dataclasses.asdict(gains)
