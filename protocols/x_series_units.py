"""The X-series servos' units (XM430, XL430), as Dynamixel protocol 2.0's control table holds
them (``protocols.dynamixel_v2``): joint angles and speeds in and out of the table's values.

Position 0..4095 per turn, 2048 the centre (0 rad here), counter clockwise positive;
velocities (Present Velocity, signed; Goal and Profile Velocity and Velocity Limit) 0.229 rpm
per unit. Profile Velocity 0 means no limit but the Velocity Limit, not stop.
"""

from __future__ import annotations

import math

from protocols.dynamixel_common import PositionScale, speed_limit

RETURN_DELAY_US_PER_UNIT = 2.0
"""Return Delay Time: 2 us per unit."""
POSITION_CENTER = 2048
POSITION_MAX = 4095
POSITION_UNITS_PER_RAD = 4096 / (2.0 * math.pi)
"""4096 steps a turn (0.088 degree each), 2048 the centre."""
VELOCITY_RAD_S_PER_UNIT = 0.229 * 2.0 * math.pi / 60.0
"""0.229 rpm per unit."""
PROFILE_VELOCITY_MAX = 32767

_POSITIONS = PositionScale(POSITION_CENTER, POSITION_UNITS_PER_RAD, POSITION_MAX, math.pi + 1.0)
position_of_angle = _POSITIONS.of_angle
"""2048 + angle * 4096 / 2 pi: the Goal Position of an angle, before rounding."""
position_units = _POSITIONS.units
"""Goal Position of a joint angle (rad, 0 at the centre), clamped to 0..4095."""
angle_of_units = _POSITIONS.angle


def profile_velocity(rad_s: float) -> int | None:
    """Profile Velocity of a speed magnitude: round(|rad_s| / 0.024), at most 32767; None when
    that is 0, for Profile Velocity 0 means no limit: a joint that slow must hold. ValueError
    for a non-finite speed."""
    return speed_limit(rad_s, VELOCITY_RAD_S_PER_UNIT, PROFILE_VELOCITY_MAX, "profile velocity")


def velocity_units(rad_s: float) -> int:
    """Present or Goal Velocity (signed) of a joint velocity (rad/s)."""
    return round(rad_s / VELOCITY_RAD_S_PER_UNIT)


def rad_s_of_velocity_units(units: int) -> float:
    """Joint velocity (rad/s) of a (signed) velocity value."""
    return units * VELOCITY_RAD_S_PER_UNIT
