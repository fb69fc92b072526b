"""A 2D pymunk world: a base of the robot's kind, a kinematic arm of its joints (revolute or
prismatic), circular obstacles and, for a differential base, wheel encoders. Pure simulation:
no I/O. Solids in 3-D (``wbc.geometry.obstacles3d``)
stop nothing: the world counts the penetrations of the robot's collision parts into them, from the
kinematics (``wbc.geometry.arm_clearance``), as pymunk counts the base's contacts.

The base is a dynamic disc tied to a kinematic control body by a PivotJoint and a GearJoint
(max_bias 0, max_force = friction), as in pymunk's tank example: the joints make the disc take
the control body's velocity, so the base rolls without sliding sideways (5.11) unless an
obstacle pushes harder than the friction force. Wheel speeds (l, r) drive it as a unicycle,
v = (r + l)/2, omega = (r - l)/b (b the wheel base).

An omnidirectional base is the same disc with the control body driven by the commanded
(forward, lateral, angular) velocity in the base's frame instead of by wheels (``drive``); its
odometry is the base's pose relative to where it started (no wheels to count). A fixed base is
a kinematic body that never moves.

Chipmunk integrates positions with the velocities solved in the previous step (semi-implicit
Euler), so the base moves with a wheel command one step after it is set.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pymunk

from wbc.geometry.arm_clearance import PenetrationCount, part_clearances
from wbc.geometry.obstacles import Circle
from wbc.geometry.obstacles3d import Solid
from wbc.robot import BASE_DOF, BaseDescription, MobileManipulator

BASE_COLLISION_TYPE = 1
OBSTACLE_COLLISION_TYPE = 2
CONTACT_SLOP = 1e-4
"""Penetration (m) pymunk allows before pushing shapes apart (its default, 0.1, is for pixels)."""
CONTACT_FRICTION = 1.0
"""Friction coefficient of base and obstacles. The isotropic joints push the base along its
heading, so without contact friction a base driving into an off-centre post slides sideways
around it (0.21 m in 4 s at 0.3 m/s, 5 cm off centre), which its wheels do not allow."""
SOLVER_ITERATIONS = 100
"""Driving head-on into a post at 0.3 m/s (dt 0.01 s, friction_force 1e4 N), the stiff joints
push the base 22 mm into it with pymunk's default 10 iterations, 0.5 mm with 100; a step costs
about 30 us either way."""


@dataclass(frozen=True)
class WorldSettings:
    """Actuator, encoder and contact parameters of the world (SI units)."""

    wheel_acceleration_max: float = 1.0
    """Largest change of each wheel's speed, m/s^2."""
    counts_per_turn: float = 508.8
    """Encoder counts per wheel turn (iRobot Create 2)."""
    encoder_noise_counts: float = 0.0
    """Standard deviation of the Gaussian noise added to each wheel's count increment per step."""
    wheel_slip: float = 0.0
    """Per step, each wheel measures (1 + wheel_slip N(0, 1)) times the distance it rolled."""
    friction_force: float = 1e4
    """Largest force (N) and torque (N m) of the joints that hold the base to its wheels."""
    base_mass: float = 3.5
    """Mass of the base disc, kg."""


def wheel_distance_per_count(robot_base: BaseDescription, counts_per_turn: float) -> float:
    """Distance (m) a wheel rolls per encoder count: pi d / counts_per_turn (d = 2 r_wheel)."""
    return math.pi * 2.0 * robot_base.wheel_radius / counts_per_turn


def _sinc(x: float) -> float:
    """sin(x)/x, with its Taylor series 1 - x^2/6 near 0."""
    return math.sin(x) / x if abs(x) > 1e-9 else 1.0 - x * x / 6.0


def _accelerate(speed: float, target: float, step_max: float) -> float:
    """s + clip(target - s, -step_max, step_max): one step towards target under a rate limit."""
    return speed + min(max(target - speed, -step_max), step_max)


class World:
    """The robot in a plane of static circular obstacles, stepped with a fixed dt."""

    def __init__(
        self,
        robot: MobileManipulator,
        q0: np.ndarray,
        obstacles: Sequence[Circle],
        settings: WorldSettings = WorldSettings(),  # noqa: B008 (frozen, so sharing is safe)
        seed: int = 0,
        solids: Sequence[Solid] = (),
    ) -> None:
        q0 = np.array(q0, dtype=float)
        if q0.shape != (robot.dof,) or not np.all(np.isfinite(q0)):
            raise ValueError(f"q0 must be {robot.dof} finite values, got {q0.tolist()}")
        self._arm_min, self._arm_max = robot.q_min[BASE_DOF:], robot.q_max[BASE_DOF:]
        if np.any(q0[BASE_DOF:] < self._arm_min) or np.any(q0[BASE_DOF:] > self._arm_max):
            raise ValueError(f"q0 arm joints {q0[BASE_DOF:].tolist()} are outside their limits")
        self.robot = robot
        self.settings = settings
        self._rng = np.random.default_rng(seed)
        self._space = pymunk.Space()
        self._space.collision_slop = CONTACT_SLOP
        self._space.iterations = SOLVER_ITERATIONS
        self._start = tuple(float(v) for v in q0[:BASE_DOF])
        self._body, self._control = self._add_base(q0[:BASE_DOF])
        for obstacle in obstacles:
            shape = pymunk.Circle(
                self._space.static_body, obstacle.radius, (obstacle.x, obstacle.y)
            )
            shape.collision_type, shape.friction = OBSTACLE_COLLISION_TYPE, CONTACT_FRICTION
            self._space.add(shape)
        self._space.on_collision(
            BASE_COLLISION_TYPE, OBSTACLE_COLLISION_TYPE, begin=self._begin, separate=self._separate
        )
        self._q_arm = q0[BASE_DOF:].copy()
        self._arm_command = np.zeros(robot.arm_dof)
        self._arm_velocity = np.zeros(robot.arm_dof)
        self._wheel_targets = (0.0, 0.0)
        self._wheels = (0.0, 0.0)
        self._body_velocity = (0.0, 0.0, 0.0)
        self._counts = np.zeros(2)
        self._contacts = 0
        self._touching = 0
        self._time = 0.0
        self._solids = tuple(solids)
        self._penetrations = PenetrationCount()
        self._count_penetrations()

    def _add_base(self, pose: np.ndarray) -> tuple[pymunk.Body, pymunk.Body]:
        """The base disc and the kinematic body whose velocity it follows through two joints;
        a fixed base's disc is a kinematic body that never moves (its own control body)."""
        mass, radius = self.settings.base_mass, self.robot.base.body_radius
        if self.robot.base.kind == "fixed":
            body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        else:
            body = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0.0, radius))
        body.position, body.angle = (pose[0], pose[1]), pose[2]
        shape = pymunk.Circle(body, radius)
        shape.collision_type, shape.friction = BASE_COLLISION_TYPE, CONTACT_FRICTION
        if self.robot.base.kind == "fixed":
            self._space.add(body, shape)
            return body, body
        control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        control.position, control.angle = body.position, body.angle
        pivot = pymunk.PivotJoint(control, body, (0.0, 0.0), (0.0, 0.0))
        gear = pymunk.GearJoint(control, body, 0.0, 1.0)
        for joint in (pivot, gear):
            joint.max_bias = 0.0
            joint.max_force = self.settings.friction_force
        self._space.add(body, shape, control, pivot, gear)
        return body, control

    def _begin(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        self._contacts += 1
        self._touching += 1

    def _separate(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        self._touching -= 1

    def command(
        self, left_wheel: float, right_wheel: float, joint_velocities: Sequence[float]
    ) -> None:
        """Hold wheel speed targets (m/s, clipped to +-wheel_speed_max) and arm joint velocities
        (rad/s, m/s for a prismatic joint) until the next command (a differential base's)."""
        if self.robot.base.kind != "differential":
            raise ValueError(f"a {self.robot.base.kind} base has no wheels to command")
        if not (math.isfinite(left_wheel) and math.isfinite(right_wheel)):
            raise ValueError(f"wheel speeds must be finite, got {left_wheel}, {right_wheel}")
        self._arm_command = self._joint_velocities(joint_velocities)
        limit = self.robot.base.wheel_speed_max
        self._wheel_targets = (
            min(max(left_wheel, -limit), limit),
            min(max(right_wheel, -limit), limit),
        )

    def drive(
        self, forward: float, lateral: float, angular: float, joint_velocities: Sequence[float]
    ) -> None:
        """Hold the base's velocity in its own frame (forward and lateral m/s, angular rad/s,
        each clipped to the base's bound on u_b) and the arm joint velocities until the next
        command: an omnidirectional base's; a fixed base takes the joints and never moves."""
        if self.robot.base.kind == "differential":
            raise ValueError("a differential base is commanded by its wheels")
        velocity = np.array([forward, lateral, angular], dtype=float)
        if not np.all(np.isfinite(velocity)):
            raise ValueError(f"base velocity must be finite, got {velocity.tolist()}")
        self._arm_command = self._joint_velocities(joint_velocities)
        bound = self.robot.base.velocity_max
        self._body_velocity = tuple(np.clip(velocity, -bound, bound).tolist())

    def _joint_velocities(self, joint_velocities: Sequence[float]) -> np.ndarray:
        qdot = np.array(joint_velocities, dtype=float)
        if qdot.shape != (self.robot.arm_dof,) or not np.all(np.isfinite(qdot)):
            raise ValueError(
                f"joint_velocities must be {self.robot.arm_dof} finite values, got {qdot.tolist()}"
            )
        return qdot

    def stop(self) -> None:
        """Zero the base and joint targets; wheels slow down at the acceleration limit."""
        if self.robot.base.kind == "differential":
            self.command(0.0, 0.0, np.zeros(self.robot.arm_dof))
        else:
            self.drive(0.0, 0.0, 0.0, np.zeros(self.robot.arm_dof))

    def step(self, dt: float) -> None:
        """Advance the world by dt seconds: wheels, base physics, arm, encoders."""
        if not (dt > 0.0 and math.isfinite(dt)):
            raise ValueError(f"dt must be a positive number of seconds, got {dt}")
        step_max = self.settings.wheel_acceleration_max * dt
        self._wheels = (
            _accelerate(self._wheels[0], self._wheel_targets[0], step_max),
            _accelerate(self._wheels[1], self._wheel_targets[1], step_max),
        )
        kind = self.robot.base.kind
        if kind == "differential":
            self._drive_control_body(dt)
        elif kind == "omnidirectional":
            self._drive_body_velocity(dt)
        before = (self._body.position, self._body.angle)
        self._space.step(dt)
        self._step_arm(dt)
        if kind == "differential":
            self._step_encoders(*before)
        self._time += dt
        self._count_penetrations()

    def _count_penetrations(self) -> None:
        if self._solids:
            self._penetrations.update(part_clearances(self.robot, self.q, self._solids))

    def _drive_control_body(self, dt: float) -> None:
        """Control velocity v sinc(omega dt/2) along heading theta + omega dt/2: the chord of the
        unicycle arc of the step in which the base will move with it, the next one, which starts
        at theta = phi + phi' dt."""
        left, right = self._wheels
        forward, angular = 0.5 * (right + left), (right - left) / self.robot.base.wheel_base
        half_turn = 0.5 * angular * dt
        heading = self._body.angle + self._body.angular_velocity * dt + half_turn
        speed = forward * _sinc(half_turn)
        self._control.velocity = (speed * math.cos(heading), speed * math.sin(heading))
        self._control.angular_velocity = angular

    def _drive_body_velocity(self, dt: float) -> None:
        """Control velocity: the commanded (forward, lateral) turned into the world frame at
        the heading of the middle of the step in which the base moves with it, the next."""
        forward, lateral, angular = self._body_velocity
        heading = self._body.angle + self._body.angular_velocity * dt + 0.5 * angular * dt
        c, s = math.cos(heading), math.sin(heading)
        self._control.velocity = (c * forward - s * lateral, s * forward + c * lateral)
        self._control.angular_velocity = angular

    def _step_arm(self, dt: float) -> None:
        """q_arm <- clip(q_arm + q' dt, q_min, q_max); q' reads 0 where a stop blocks it."""
        self._q_arm = np.clip(self._q_arm + self._arm_command * dt, self._arm_min, self._arm_max)
        blocked = ((self._q_arm >= self._arm_max) & (self._arm_command > 0.0)) | (
            (self._q_arm <= self._arm_min) & (self._arm_command < 0.0)
        )
        self._arm_velocity = np.where(blocked, 0.0, self._arm_command)

    def _step_encoders(self, position: pymunk.Vec2d, angle: float) -> None:
        """Wheel distances of the base's motion in the step, inverting wbc.base_motion's
        dead reckoning: dphi = Delta angle, ds = (Delta p . heading(phi + dphi/2)) / sinc(dphi/2),
        d_l,r = ds -+ dphi b/2; each measured as (1 + slip N) d, plus noise N counts."""
        dphi = self._body.angle - angle
        mid = angle + 0.5 * dphi
        moved = self._body.position - position
        ds = (moved.x * math.cos(mid) + moved.y * math.sin(mid)) / _sinc(0.5 * dphi)
        half_track = 0.5 * dphi * self.robot.base.wheel_base
        distances = np.array([ds - half_track, ds + half_track])
        slip, noise = self._rng.standard_normal(2), self._rng.standard_normal(2)
        measured = distances * (1.0 + self.settings.wheel_slip * slip)
        per_count = wheel_distance_per_count(self.robot.base, self.settings.counts_per_turn)
        self._counts += measured / per_count + self.settings.encoder_noise_counts * noise

    @property
    def q(self) -> np.ndarray:
        """Ground truth [x, y, phi, q1..qn]; phi is continuous, not wrapped."""
        x, y = self._body.position
        return np.concatenate(([x, y, self._body.angle], self._q_arm))

    @property
    def end_effector(self) -> np.ndarray:
        """vec8 of the end-effector pose, robot.fkm(q) (4.6)."""
        return self.robot.fkm(self.q)

    @property
    def odometry_pose(self) -> tuple[float, float, float]:
        """The base's pose in the frame of its start pose: what an omnidirectional or fixed
        base's odometry reads (exact: no wheels slip)."""
        x0, y0, phi0 = self._start
        x, y = self._body.position
        dx, dy = x - x0, y - y0
        c, s = math.cos(phi0), math.sin(phi0)
        return c * dx + s * dy, -s * dx + c * dy, self._body.angle - phi0

    @property
    def base_velocity(self) -> tuple[float, float, float]:
        """The base's (forward, lateral, angular) velocity in its own frame, m/s and rad/s."""
        vx, vy = self._body.velocity
        c, s = math.cos(self._body.angle), math.sin(self._body.angle)
        return c * vx + s * vy, -s * vx + c * vy, self._body.angular_velocity

    @property
    def wheel_speeds(self) -> tuple[float, float]:
        """(left, right) wheel speeds (m/s) after the acceleration limit."""
        return self._wheels

    @property
    def joint_velocities(self) -> np.ndarray:
        """Arm joint velocities (rad/s) of the last step, 0 where a joint sits at a stop."""
        return self._arm_velocity.copy()

    @property
    def encoder_counts(self) -> tuple[int, int]:
        """Cumulative measured (left, right) counts, rounded down."""
        return math.floor(self._counts[0]), math.floor(self._counts[1])

    @property
    def contacts(self) -> int:
        """Number of base-obstacle contacts that began so far."""
        return self._contacts

    @property
    def in_contact(self) -> bool:
        """Whether the base touches an obstacle now."""
        return self._touching > 0

    @property
    def arm_penetrations(self) -> int:
        """Number of penetrations of a collision part into a solid that began so far (one at
        the start counts)."""
        return self._penetrations.count

    @property
    def arm_penetrating(self) -> bool:
        """Whether a collision part penetrates a solid now."""
        return self._penetrations.penetrating

    @property
    def time_s(self) -> float:
        """Simulated time, s."""
        return self._time
