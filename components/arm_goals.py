"""Where the arm driver (``components.arm_driver``) aims each joint, in its servo bus's Goal
Position units: ahead of the joint's present position in the direction of motion
(``lookahead_s`` of the commanded speed, at least ``min_step`` units) at the commanded speed;
or, for a joint whose speed rounds to 0 (which would mean full speed), the goal it holds: where
it was read when it stopped, kept while it stays stopped, so it does not creep. Every goal lies
inside the robot description's joint limits (mapped to servo angles by ``wbc.servo_map``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from components.servo_bus import HOLD_SPEED, ServoBus
from wbc.servo_map import ServoMap


class ArmGoals:
    """The goals of the joints of ``servos`` on ``bus``, between the joint limits ``low`` and
    ``high`` (rad), ahead by the driver's ``params`` (see the module docstring)."""

    def __init__(
        self,
        servos: ServoMap,
        bus: ServoBus,
        low: np.ndarray,
        high: np.ndarray,
        params: Mapping[str, object],
    ) -> None:
        self.servos, self.bus, self.params = servos, bus, params
        joints = range(len(servos.ids))
        ends = [
            sorted((servos.servo_angle(i, low[i]), servos.servo_angle(i, high[i]))) for i in joints
        ]
        self.goal_low = [max(0, math.ceil(bus.position_of_angle(low))) for low, _ in ends]
        self.goal_high = [
            min(bus.position_max, math.floor(bus.position_of_angle(high))) for _, high in ends
        ]
        """The Goal Positions inside the joint limits (every goal written lies in them)."""
        self.held: list[int | None] = [None] * len(joints)
        """The goal a stopped joint holds, units; None while it moves."""

    def ahead(self, index: int, velocity: float, present: float) -> tuple[int, int]:
        """Joint ``index``'s goal (units) and Moving Speed for a finite ``velocity`` (rad/s),
        from its ``present`` position (rad)."""
        speed = self.bus.speed_units(velocity)
        if speed is None:
            return self.holding(index, present), HOLD_SPEED
        self.held[index] = None
        step = max(
            abs(velocity) * self.params["lookahead_s"],
            self.params["min_step"] / self.bus.units_per_rad,
        )
        return self.inside_limits(index, present + math.copysign(step, velocity)), speed

    def holding(self, index: int, present: float) -> int:
        """The goal joint ``index`` holds: ``present`` (where it was read when it stopped, the
        last good reading if its servo did not answer then), kept while it stays stopped."""
        if self.held[index] is None:
            self.held[index] = self.inside_limits(index, present)
        return self.held[index]

    def inside_limits(self, index: int, q: float) -> int:
        """The Goal Position of joint position ``q`` (finite), clamped to the joint's limits in
        units."""
        units = self.bus.position_units(self.servos.servo_angle(index, q))
        return min(max(units, self.goal_low[index]), self.goal_high[index])

    def check(self, ids: Sequence[int], goals: Sequence[int], speeds: Sequence[int]) -> None:
        """``ValueError`` unless every goal lies inside its joint's limits and every speed is
        one the bus can write."""
        for index, (servo, goal, speed) in enumerate(zip(ids, goals, speeds, strict=True)):
            if not (
                self.goal_low[index] <= goal <= self.goal_high[index]
                and 1 <= speed <= self.bus.speed_max
            ):
                raise ValueError(f"servo {servo}: goal {goal} or speed {speed} out of range")
