"""Turn the base towards where it should stand for a pose goal: w s |phi' - k angle_to(T)|.

A differential-drive base cannot move sideways, so it must face the place it has to reach
before it drives there. For a pose goal that place T is not the goal itself but a set-back
``reach`` behind it, along the goal gripper's heading psi: T = p_d,xy - reach (cos psi,
sin psi). The heading is the yaw of the gripper's y axis less pi/2: with the wrist joints at
zero it is the yaw of the arm's plane (phi + q1) and of the gripper's approach (x) axis, and
unlike the approach axis it stays defined when the gripper points down.

The term asks phi' = k wrap(atan2(T - q_xy) - phi). The turn it asks for costs the task
nothing: phi' = -q1' moves no part of the end effector, and the waist centring term
(wbc.laws.objectives.waist_centring) takes the waist back afterwards. Its weight ramps from 0 at
``stop_distance`` from T to w at twice that distance, so the base stops steering as it arrives
and the task alone places it. Position goals have no heading: the term is idle for them.

Steering through the self-motion costs one more nonzero entry of u, so the term steers in
bursts: from a heading error above ``on`` until it is below ``off`` (a latch). Steering at
every step, as a band's edge would, kept 8 entries in most moving steps; in bursts (0.3 and
0.05 rad, k 4) the 'ahead' goals of `parsimony bench` are reached as often (0.94) with 7.

A goal high above the floor leaves the arm little horizontal reach: over the 1,800 goals of the
three families ahead (``studies.goal_families``, seeds 2-7) the gripper stands 0.37 m from
its base at a height of 0.5 m, 0.21 at 0.65 and 0.11 at 0.7. Set back 0.36 m, the target then
lies behind the base's own goal: the base drives past it and turns round to face it.
``base_target_shrink`` shortens the set-back by that much per metre of the goal gripper's height
above ``base_target_high`` (1.7 follows those means), and ``base_target_ahead_only`` never
steers towards a target behind the base. Both are off by default: on the held-out seeds 20-22
of 'ahead, wide arm' they raise the share reached from 0.72 to 0.82 (7 entries while moving),
short of the 0.9 sought, while 'ahead, any arm start' goes from 0.947 to 0.937 on the same
seeds and the 'ahead' goals of `parsimony bench` (seed 2) from 0.94 to 0.92
(the study ``studies/files/goal-reach.yaml``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc import dq
from wbc.laws.gains import gain
from wbc.laws.kept import zeros
from wbc.laws.objectives.base import Latch, ResidualCost, unit_row
from wbc.laws.step_context import StepContext
from wbc.planar import wrap

J_AXIS = np.array([0.0, 0.0, 1.0, 0.0])
"""The pure quaternion j: the end effector's y axis in its own frame."""


def gripper_heading(goal_pose: np.ndarray) -> float:
    """psi: yaw of the end effector's y axis, less pi/2."""
    rotation = dq.rotation(goal_pose)
    y_axis = dq.qmul(dq.qmul(rotation, J_AXIS), dq.qconj(rotation))
    return math.atan2(y_axis[2], y_axis[1]) - 0.5 * math.pi


@dataclass(frozen=True)
class BaseTargetGains:
    base_target: float = gain(
        0.05,
        low=0.0,
        high=1.0,
        doc="weight of turning the base towards where it should stand "
        "for a pose goal (wbc.laws.objectives.base_target)",
    )
    base_target_gain: float = gain(4.0, low=1e-3, high=100.0, doc="k of the base target, 1/s")
    base_target_reach: float = gain(
        0.36,
        low=0.0,
        high=5.0,
        doc="how far behind the goal, along the gripper's heading, "
        "the base should stand, m: the mean horizontal reach "
        "over the arm goals of `parsimony bench` (0.36 +- 0.08)",
    )
    base_target_high: float = gain(
        0.55,
        low=0.0,
        high=5.0,
        doc="height of the goal's gripper above which the set-back shrinks, m",
    )
    base_target_shrink: float = gain(
        0.0,
        low=0.0,
        high=100.0,
        doc="how much the set-back shrinks per m of the goal gripper's height above "
        "base_target_high (0: never), m/m",
    )
    base_target_ahead_only: bool = gain(
        False, doc="steer only towards a base target ahead of the base (bearing within 90 degrees)"
    )
    base_target_stop: float = gain(
        0.15,
        low=1e-3,
        high=5.0,
        doc="distance from the base target within which it is off (full weight at twice), m",
    )
    base_target_on: float = gain(
        0.3,
        low=0.0,
        high=3.2,
        doc="heading error above which the base target starts a steering burst, rad (0: always on)",
    )
    base_target_off: float = gain(
        0.05, low=0.0, high=3.2, doc="heading error below which a steering burst ends, rad"
    )

    @staticmethod
    def check_together(params: object) -> None:
        """A burst ends below the heading error it starts at."""
        if params.base_target_on > 0.0 and not params.base_target_off < params.base_target_on:
            raise ValueError(
                f"{type(params).__name__}.base_target_off must be below "
                f"base_target_on ({params.base_target_on}), got "
                f"{params.base_target_off}"
            )


class BaseTarget:
    """weight * s * |phi' - gain * wrap(bearing(T) - phi)|, s = clip(d / stop - 1, 0, 1), while
    the latch on the heading error is engaged."""

    name = "base_target"

    gains: ClassVar[tuple[type, ...]] = (BaseTargetGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> BaseTarget | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        on = params.base_target > 0.0
        return (
            cls(
                params.base_target,
                params.base_target_gain,
                params.base_target_reach,
                params.base_target_stop,
                params.base_target_on,
                params.base_target_off,
                params.base_target_high,
                params.base_target_shrink,
                params.base_target_ahead_only,
            )
            if on
            else None
        )

    def __init__(
        self,
        weight: float,
        gain: float,
        reach: float,
        stop_distance: float,
        on: float = 0.0,
        off: float = 0.0,
        high: float = 0.0,
        shrink: float = 0.0,
        ahead_only: bool = False,
    ) -> None:
        if not (weight >= 0.0 and gain > 0.0 and reach >= 0.0 and stop_distance > 0.0):
            raise ValueError(
                "base target needs weight >= 0, gain > 0, reach >= 0 and stop_distance > 0"
            )
        self.weight, self.gain = weight, gain
        self.reach, self.stop_distance = reach, stop_distance
        self.latch = Latch(on, off) if on > 0.0 else None
        self.high, self.shrink, self.ahead_only = high, shrink, ahead_only
        self._goal_pose: np.ndarray | None = None
        self._target = (0.0, 0.0)

    def target(self, goal_pose: np.ndarray) -> tuple[float, float]:
        """T: the goal's floor position, set back by ``reach`` along the gripper's heading.

        Kept while the goal pose is the same object (a task's pose is read-only), so a step
        does not compute it again.
        """
        if goal_pose is not self._goal_pose:
            psi = gripper_heading(goal_pose)
            position = dq.translation(goal_pose)
            self._goal_pose = goal_pose
            reach = max(0.0, self.reach - self.shrink * max(0.0, position[3] - self.high))
            self._target = (
                position[1] - reach * math.cos(psi),
                position[2] - reach * math.sin(psi),
            )
        return self._target

    def cost(self, context: StepContext) -> ResidualCost:
        row = unit_row(context.robot.dof, 2)
        if context.goal_pose is None:
            return ResidualCost(self.name, row, zeros(1), 0.0)
        x, y, phi = context.q[:3].tolist()
        target_x, target_y = self.target(context.goal_pose)
        distance = math.hypot(target_x - x, target_y - y)
        ramp = min(1.0, max(0.0, distance / self.stop_distance - 1.0))
        turn = wrap(math.atan2(target_y - y, target_x - x) - phi)
        ahead = not self.ahead_only or abs(turn) <= 0.5 * math.pi
        steering = ramp > 0.0 and ahead and (self.latch is None or self.latch.update(turn))
        if not steering:
            if self.latch is not None:
                self.latch.engaged = False
            return ResidualCost(self.name, row, zeros(1), 0.0)
        return ResidualCost(self.name, row, np.array([-self.gain * turn]), self.weight * ramp)

    def reset(self) -> None:
        if self.latch is not None:
            self.latch.engaged = False
