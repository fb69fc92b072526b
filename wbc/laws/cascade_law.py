"""The cascade of appendix B: a pseudoinverse outer loop, a linearising inner loop for the base.

The outer loop computes u = -J^+ eta e for a holonomic base (B.1). Its base part u_b drives a
reference base (x_r, y_r, phi_r), integrated over time. The inner loop makes the offset point
(x1, y1) = (x + d cos phi, y + d sin phi) of the real, nonholonomic base track the same point
of the reference by input-output linearisation (Skaar 2007):

    [u1, u2] = [x1_r', y1_r'] + diag(k1, k2) [x1_r - x1, y1_r - y1]
    phi' = (u2 cos phi - u1 sin phi) / d,   v = u1 cos phi + u2 sin phi

and the base part of the output is (v cos phi, v sin phi, phi'), which obeys 5.11 exactly.
The reference point is kept within ``max_lead`` of the real one (anti-windup).

Appendix B bounds nothing. With ``saturate`` the output is what the robot would carry out
(``saturated``): the bounds on u the LP obeys and the wheel speed limit, all read from the
robot's description.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from wbc.base_motion import unicycle, wheel_speeds
from wbc.geometry.obstacles import Obstacle
from wbc.laws.gains import check_gains, gain
from wbc.laws.law_output import LawOutput, summarise
from wbc.laws.pinv_law import pinv_velocity
from wbc.robot import BASE_DOF, MobileManipulator
from wbc.task import MEASUREMENT_TOLERANCE, Task, same_task
from wbc.validation import require_finite

Array = np.ndarray


@dataclass(frozen=True)
class CascadeParams:
    eta: float = gain(0.6, low=1e-3, high=100.0, doc="outer-loop task gain, 1/s")
    offset: float = gain(
        0.1, low=0.01, high=1.0, doc="d, the tracked point's distance ahead of the wheel axle, m"
    )
    k1: float = gain(2.0, low=1e-3, high=100.0, doc="inner-loop gain on x1, 1/s")
    k2: float = gain(2.0, low=1e-3, high=100.0, doc="inner-loop gain on y1, 1/s")
    max_lead: float = gain(
        0.2,
        low=0.01,
        high=10.0,
        doc="how far the reference point may run ahead of the real one, m: "
        "beyond it the reference is pulled back, so a base that cannot "
        "follow does not wind the inner loop up",
    )
    saturate: bool = gain(
        False,
        doc="u as the robot carries it out: (v, omega) scaled together into the base's "
        "velocity_max and the wheel speed limit, each joint clipped to its velocity_max "
        "(False: unbounded, as appendix B)",
    )

    def __post_init__(self) -> None:
        check_gains(self)


def saturated(u: Array, phi: float, robot: MobileManipulator) -> Array:
    """u as the robot carries it out at heading ``phi``, for u whose base part obeys 5.11 (a u
    with a NaN or an infinity is returned as it is, for the caller to refuse, never clamped).

    The base: (v, omega), v = x' cos phi + y' sin phi, scaled by one factor (the path's
    curvature kept) until |x'|, |y'| and |phi'| lie inside ``robot.velocity_max`` (the LP's
    bounds), then as ``wbc.base_motion.wheel_speeds`` scales it for ``wheel_speed_max``. Each
    arm joint clipped to its ``velocity_max``, as the arm driver clips a command."""
    u = np.array(u, dtype=float)
    if not np.all(np.isfinite(u)):
        return u
    bounds = robot.velocity_max
    base = np.abs(u[:BASE_DOF])
    over = np.max(np.divide(base, bounds[:BASE_DOF], out=np.zeros(BASE_DOF), where=base > 0))
    scale = 1.0 if over <= 1.0 else 1.0 / over
    forward, angular = unicycle(u[0], u[1], u[2], phi)
    wheels = wheel_speeds(scale * forward, scale * angular, robot.base)
    u[:BASE_DOF] = wheels.forward * math.cos(phi), wheels.forward * math.sin(phi), wheels.angular
    u[BASE_DOF:] = np.clip(u[BASE_DOF:], -bounds[BASE_DOF:], bounds[BASE_DOF:])
    return u


def offset_point(x: float, y: float, phi: float, d: float) -> tuple[float, float]:
    """(x + d cos phi, y + d sin phi)."""
    return x + d * math.cos(phi), y + d * math.sin(phi)


@dataclass
class CascadeLaw:
    """Pseudoinverse outer loop, input-output linearising inner loop (appendix B)."""

    robot: MobileManipulator
    params: CascadeParams = field(default_factory=CascadeParams)
    _reference: Array | None = field(default=None, init=False, repr=False)
    _task: Task | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        if self.robot.base.kind != "differential":
            raise ValueError(
                f"the cascade law (appendix B) linearises a differential base; robot "
                f"{self.robot.name}'s base.kind is {self.robot.base.kind}: use lp, qp or classic"
            )

    def set_params(self, params: CascadeParams) -> None:
        self.params = params

    def reset(self) -> None:
        """Restart the reference base at the real one on the next step."""
        self._reference = None
        self._task = None

    def stopped(self) -> None:
        """Nothing to forget: its reference base advances only when it steps."""

    def step(
        self, q: Array, task: Task, dt: float, obstacles: Sequence[Obstacle] = ()
    ) -> LawOutput:
        """One step; the reference base advances by the outer loop's u_b over ``dt``."""
        start = time.perf_counter()
        q = require_finite("configuration q", q)
        dt = float(require_finite("dt", dt))
        if dt <= 0.0:
            raise ValueError(f"dt must be > 0, got {dt}")
        if (
            self._reference is None
            or self._task is None
            or not same_task(self._task, task, MEASUREMENT_TOLERANCE)
        ):
            self._reference = q[:3].copy()
        self._task = task

        pose, jacobian = self.robot.kinematics(q)
        error, task_jacobian = task.error(pose, jacobian, q)
        reference_u = pinv_velocity(task_jacobian, error, self.params.eta)
        x_r, y_r, phi_r = self._reference
        xr_dot, yr_dot, phir_dot = reference_u[:3]
        d = self.params.offset
        target_x, target_y = offset_point(x_r, y_r, phi_r, d)
        target_x_dot = xr_dot - d * math.sin(phi_r) * phir_dot
        target_y_dot = yr_dot + d * math.cos(phi_r) * phir_dot

        x, y, phi = q[0], q[1], q[2]
        point_x, point_y = offset_point(x, y, phi, d)
        lead = math.hypot(target_x - point_x, target_y - point_y)
        if lead > self.params.max_lead:
            pull = 1.0 - self.params.max_lead / lead
            shift_x, shift_y = pull * (point_x - target_x), pull * (point_y - target_y)
            target_x, target_y = target_x + shift_x, target_y + shift_y
            self._reference = self._reference + np.array([shift_x, shift_y, 0.0])
        u1 = target_x_dot + self.params.k1 * (target_x - point_x)
        u2 = target_y_dot + self.params.k2 * (target_y - point_y)
        forward = u1 * math.cos(phi) + u2 * math.sin(phi)
        angular = (u2 * math.cos(phi) - u1 * math.sin(phi)) / d

        self._reference = self._reference + dt * reference_u[:3]
        u = reference_u.copy()
        u[:3] = forward * math.cos(phi), forward * math.sin(phi), angular
        if self.params.saturate:
            u = saturated(u, phi, self.robot)
        return summarise(u, "optimal", None, (), error, start)
