"""From the base part of u to what a differential-drive base takes: (v, omega) and wheel speeds."""

from __future__ import annotations

import math
from dataclasses import dataclass

from wbc.robot import BaseDescription


@dataclass(frozen=True)
class BaseVelocity:
    """Forward velocity v (m/s), angular velocity omega (rad/s) and the wheel speeds (m/s)."""

    forward: float
    angular: float
    left_wheel: float
    right_wheel: float
    scale: float
    """Factor (<= 1) applied to (v, omega) so that no wheel exceeds its limit."""


def unicycle(x_dot: float, y_dot: float, phi_dot: float, phi: float) -> tuple[float, float]:
    """v = x' cos(phi) + y' sin(phi), omega = phi' (exact when u obeys 5.11)."""
    return x_dot * math.cos(phi) + y_dot * math.sin(phi), phi_dot


def wheel_speeds(forward: float, angular: float, base: BaseDescription) -> BaseVelocity:
    """Wheel speeds v -+ omega b / 2 (b the wheel base), scaled together when one is too fast.

    Scaling v and omega by one factor keeps the path's curvature; the robot only slows down.
    """
    if not (math.isfinite(forward) and math.isfinite(angular)):
        raise ValueError(f"base velocity must be finite, got v={forward}, omega={angular}")
    half_track = 0.5 * base.wheel_base * angular
    left, right = forward - half_track, forward + half_track
    fastest = max(abs(left), abs(right))
    scale = 1.0 if fastest <= base.wheel_speed_max else base.wheel_speed_max / fastest
    return BaseVelocity(forward * scale, angular * scale, left * scale, right * scale, scale)


def dead_reckoning(
    x: float, y: float, phi: float, d_left: float, d_right: float, wheel_base: float
) -> tuple[float, float, float]:
    """The pose after the wheels roll ``d_left`` and ``d_right`` (m) along a circular arc:
    ds = (d_r + d_l)/2, dphi = (d_r - d_l)/b, and the chord of the arc,
    x += ds sinc(dphi/2) cos(phi + dphi/2), y += ds sinc(dphi/2) sin(phi + dphi/2)."""
    ds, dphi = 0.5 * (d_right + d_left), (d_right - d_left) / wheel_base
    half = 0.5 * dphi
    chord = ds * (math.sin(half) / half if abs(half) > 1e-9 else 1.0 - half * half / 6.0)
    heading = phi + half
    return x + chord * math.cos(heading), y + chord * math.sin(heading), phi + dphi
