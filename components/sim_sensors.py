"""What the simulator's sensors read off its world each step, as the real robot's drivers
report it: the servos' joint states (named as the robot's description names them), the
Create's wheel odometry (the encoder counts, with the world's noise and slip, the distances and
the pose dead-reckoned from them; an omnidirectional or fixed base reports its pose from where
it started, no wheels) and the ground truth (tests and reports only)."""

from __future__ import annotations

from messages.header import Header
from messages.joints import JointStates
from messages.obstacles import Circle, Solids
from messages.odometry import BaseOdometry
from messages.truth import SimTruth
from profiles.scene import Scene
from sim2d.scenarios import goal_above
from sim2d.world import World, wheel_distance_per_count
from wbc.base_motion import dead_reckoning


class SimSensors:
    """The readings of ``world`` (its robot's wheel encoders of ``counts_per_turn``), in the
    world of ``scene``, its ``obstacles`` and ``solids``."""

    def __init__(
        self,
        world: World,
        scene: Scene,
        obstacles: tuple[Circle, ...],
        solids: Solids,
        counts_per_turn: int,
    ) -> None:
        self.world, self.scene = world, scene
        self.obstacles, self.solids = obstacles, solids
        self.wheels = world.robot.base.kind == "differential"
        self.wheel_base = world.robot.base.wheel_base
        self.metres_per_count = (
            wheel_distance_per_count(world.robot.base, counts_per_turn) if self.wheels else 0.0
        )
        self.odometry_pose = (0.0, 0.0, 0.0)
        self.last_counts = world.encoder_counts
        self.goal_of: tuple[tuple, tuple[float, ...]] = ((), ())

    def joints(self, header: Header) -> JointStates:
        return JointStates(
            header=header,
            names=self.world.robot.joint_names,
            positions=tuple(self.world.q[3:].tolist()),
            velocities=tuple(self.world.joint_velocities.tolist()),
        )

    def odometry(self, header: Header) -> BaseOdometry:
        """The counts, the distances and the pose dead-reckoned since the last reading; a base
        without wheels: its pose from where it started and its velocity."""
        if not self.wheels:
            x, y, phi = self.world.odometry_pose
            forward, _, angular = self.world.base_velocity
            return BaseOdometry(
                header=header,
                left_encoder=0,
                right_encoder=0,
                left_distance=0.0,
                right_distance=0.0,
                x=x,
                y=y,
                phi=phi,
                forward_velocity=forward,
                angular_velocity=angular,
            )
        counts = self.world.encoder_counts
        d_left, d_right = (
            (c - c0) * self.metres_per_count for c, c0 in zip(counts, self.last_counts, strict=True)
        )
        self.last_counts = counts
        self.odometry_pose = dead_reckoning(*self.odometry_pose, d_left, d_right, self.wheel_base)
        left, right = self.world.wheel_speeds
        x, y, phi = self.odometry_pose
        return BaseOdometry(
            header=header,
            left_encoder=counts[0],
            right_encoder=counts[1],
            left_distance=counts[0] * self.metres_per_count,
            right_distance=counts[1] * self.metres_per_count,
            x=x,
            y=y,
            phi=phi,
            forward_velocity=0.5 * (left + right),
            angular_velocity=(right - left) / self.wheel_base,
        )

    def truth(self, header: Header, goal_marker: tuple[float, ...]) -> SimTruth:
        """The real pose, joints, end effector, contacts, the goal of the bin marker at
        ``goal_marker`` ([x, y, yaw]) and the arm's penetrations into the solids."""
        world = self.world
        return SimTruth(
            header=header,
            base_pose=tuple(world.q[:3].tolist()),
            arm_joints=tuple(world.q[3:].tolist()),
            end_effector=tuple(world.end_effector.tolist()),
            contacts=world.contacts,
            in_contact=world.in_contact,
            goal=self._goal(goal_marker),
            reference_pose=self.scene.reference_pose,
            obstacles=self.obstacles,
            solids=self.solids,
            arm_penetrations=world.arm_penetrations,
            arm_penetrating=world.arm_penetrating,
        )

    def _goal(self, placed: tuple[float, ...]) -> tuple[float, ...]:
        """x_d in this world (eq. 6.3): the bin marker's pose times the scene's offset; worked
        out again only when the marker moves."""
        if self.goal_of[0] != placed:
            goal = goal_above(placed, self.scene.goal.height_m, self.scene.goal.offset)
            self.goal_of = (placed, tuple(goal.tolist()))
        return self.goal_of[1]
