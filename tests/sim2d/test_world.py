"""The pymunk world (sim2d/world.py): no sideways slip, actuator limits, contacts, encoders."""

from __future__ import annotations

import math

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE
from sim2d.world import World, WorldSettings, wheel_distance_per_count
from wbc.geometry.obstacles import Circle
from wbc.geometry.obstacles3d import Plane
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
DT = 0.01
STILL_ARM = np.zeros(5)
INSTANT_WHEELS = WorldSettings(wheel_acceleration_max=1e3)
"""Wheels that reach any commanded speed in one step of DT."""


def pose(x: float, y: float, phi: float) -> np.ndarray:
    return np.array([x, y, phi, 0.0, 0.0, 0.0, 0.0, 0.0])


def run(world: World, steps: int) -> np.ndarray:
    """q before and after every step, shape (steps + 1, 8)."""
    qs = [world.q]
    for _ in range(steps):
        world.step(DT)
        qs.append(world.q)
    return np.array(qs)


def lateral_speeds(qs: np.ndarray) -> np.ndarray:
    """Body-frame y velocity of each step: Delta p . (-sin, cos)(phi + dphi/2) / dt."""
    moved = np.diff(qs, axis=0)
    mid = qs[:-1, 2] + 0.5 * moved[:, 2]
    return (-moved[:, 0] * np.sin(mid) + moved[:, 1] * np.cos(mid)) / DT


def test_straight_drive_covers_the_ramped_distance() -> None:
    """The base moves one step after a command, at speeds min(k a dt, v): d = dt sum_k s_k."""
    x0, y0, phi0, speed, steps = 1.0, -2.0, 0.7, 0.3, 100
    world = World(ROBOT, pose(x0, y0, phi0), [])
    world.command(speed, speed, STILL_ARM)
    run(world, steps)
    ramp = np.minimum(np.arange(1, steps) * 1.0 * DT, speed)
    distance = DT * ramp.sum()
    assert world.q[0] == pytest.approx(x0 + distance * math.cos(phi0), abs=1e-3)
    assert world.q[1] == pytest.approx(y0 + distance * math.sin(phi0), abs=1e-3)
    assert world.q[2] == pytest.approx(phi0, abs=1e-9)
    assert world.time_s == pytest.approx(steps * DT)


@pytest.mark.parametrize(("left", "right"), [(0.2, 0.4), (0.5, -0.1)])
def test_arc_follows_the_unicycle(left: float, right: float) -> None:
    """x = x0 + v/w (sin(phi0 + w t) - sin phi0), y = y0 - v/w (cos(phi0 + w t) - cos phi0).

    Each step moves the base along the chord of the arc, so it stays on the arc to rounding.
    """
    x0, y0, phi0, steps = 0.5, -0.3, 0.4, 200
    world = World(ROBOT, pose(x0, y0, phi0), [], INSTANT_WHEELS)
    world.command(left, right, STILL_ARM)
    run(world, steps)
    v, w, t = 0.5 * (left + right), (right - left) / ROBOT.base.wheel_base, (steps - 1) * DT
    expected = [
        x0 + v / w * (math.sin(phi0 + w * t) - math.sin(phi0)),
        y0 - v / w * (math.cos(phi0 + w * t) - math.cos(phi0)),
        phi0 + w * t,
    ]
    np.testing.assert_allclose(world.q[:3], expected, rtol=0.0, atol=1e-9)


def test_base_does_not_slide_sideways() -> None:
    """The nonholonomic constraint (5.11) is physical: body-frame lateral velocity ~ 0."""
    world = World(ROBOT, pose(0.0, 0.0, -1.0), [])
    runs = []
    for left, right in [(-0.3, 0.3), (0.1, 0.5), (0.4, 0.4), (-0.2, -0.45), (0.5, -0.5)]:
        world.command(left, right, STILL_ARM)
        runs.append(run(world, 80))
    qs = np.concatenate(runs)
    assert np.max(np.abs(lateral_speeds(qs))) < 1e-3
    travelled = np.sum(np.hypot(*np.diff(qs[:, :2], axis=0).T))
    assert travelled > 0.5 and np.ptp(qs[:, 2]) > 1.0


def test_wheel_speeds_are_clipped_to_their_limit() -> None:
    world = World(ROBOT, pose(0.0, 0.0, 0.0), [], INSTANT_WHEELS)
    world.command(2.0, -3.0, STILL_ARM)
    qs = run(world, 5)
    limit = ROBOT.base.wheel_speed_max
    assert world.wheel_speeds == (limit, -limit)
    turn_rate = (qs[-1, 2] - qs[-2, 2]) / DT
    assert turn_rate == pytest.approx(-2.0 * limit / ROBOT.base.wheel_base, rel=1e-9)


def test_wheels_obey_the_acceleration_limit() -> None:
    """s_k+1 = s_k + clip(target - s_k, -a dt, a dt), also when stopping."""
    world = World(ROBOT, pose(0.0, 0.0, 0.0), [], WorldSettings(wheel_acceleration_max=2.0))
    world.command(0.5, -0.1, STILL_ARM)
    speeds = []
    for _ in range(30):
        world.step(DT)
        speeds.append(world.wheel_speeds)
    k = np.arange(1, 31)
    np.testing.assert_allclose(np.array(speeds)[:, 0], np.minimum(0.02 * k, 0.5), atol=1e-12)
    np.testing.assert_allclose(np.array(speeds)[:, 1], np.maximum(-0.02 * k, -0.1), atol=1e-12)
    world.stop()
    world.step(DT)
    assert world.wheel_speeds == pytest.approx((0.48, -0.08), abs=1e-12)


def test_arm_joints_stop_hard_at_their_limits() -> None:
    world = World(ROBOT, pose(0.0, 0.0, 0.0), [])
    command = np.array([1.0, 1.0, -1.0, 0.5, -1.0])
    world.command(0.0, 0.0, command)
    run(world, 300)
    arm_min, arm_max = ROBOT.q_min[3:], ROBOT.q_max[3:]
    expected = [arm_max[0], arm_max[1], arm_min[2], 1.5, arm_min[4]]
    np.testing.assert_allclose(world.q[3:], expected, atol=1e-9)
    np.testing.assert_array_equal(world.joint_velocities, [0.0, 0.0, 0.0, 0.5, 0.0])
    np.testing.assert_array_equal(world.end_effector, ROBOT.fkm(world.q))
    world.command(0.0, 0.0, -command)
    world.step(DT)
    np.testing.assert_array_equal(world.joint_velocities, -command)
    assert world.q[3] == pytest.approx(arm_max[0] - DT)


def test_driving_into_an_obstacle_makes_one_contact_and_stops_the_base() -> None:
    obstacle = Circle(0.8, 0.05, 0.1)
    world = World(ROBOT, pose(0.0, 0.0, 0.0), [obstacle])
    world.command(0.3, 0.3, STILL_ARM)
    qs = run(world, 400)
    assert world.contacts == 1 and world.in_contact
    gaps = np.hypot(qs[:, 0] - obstacle.x, qs[:, 1] - obstacle.y) - obstacle.radius
    assert np.min(gaps) > ROBOT.base.body_radius - 3e-3
    assert world.q[0] < obstacle.x - ROBOT.base.body_radius
    world.command(-0.3, -0.3, STILL_ARM)
    run(world, 100)
    assert world.contacts == 1 and not world.in_contact


def test_encoder_counts_measure_the_wheel_distances() -> None:
    """counts = floor(d / (pi d_wheel / counts_per_turn)), d_l,r = ds -+ dphi b/2."""
    per_count = wheel_distance_per_count(ROBOT.base, 508.8)
    assert per_count == pytest.approx(math.pi * 0.072 / 508.8)
    world = World(ROBOT, pose(0.2, 0.1, 2.0), [])
    world.command(0.4, 0.4, STILL_ARM)
    run(world, 150)
    distance = math.hypot(world.q[0] - 0.2, world.q[1] - 0.1)
    assert distance > 0.4
    expected = math.floor(distance / per_count)
    assert all(abs(count - expected) <= 1 for count in world.encoder_counts)
    world.stop()
    run(world, 50)
    start, phi_start = world.encoder_counts, world.q[2]
    world.command(-0.3, 0.3, STILL_ARM)
    run(world, 100)
    turned = (world.q[2] - phi_start) * 0.5 * ROBOT.base.wheel_base / per_count
    assert turned > 100
    assert world.encoder_counts[0] - start[0] == pytest.approx(-turned, abs=1.5)
    assert world.encoder_counts[1] - start[1] == pytest.approx(turned, abs=1.5)


def noisy_counts(seed: int, settings: WorldSettings) -> tuple[int, int]:
    world = World(ROBOT, pose(0.0, 0.0, 0.0), [], settings, seed=seed)
    world.command(0.3, 0.35, STILL_ARM)
    run(world, 200)
    return world.encoder_counts


def test_encoder_noise_and_slip_are_reproducible_for_a_seed() -> None:
    exact = noisy_counts(0, WorldSettings())
    assert noisy_counts(7, WorldSettings()) == exact
    for noisy in [WorldSettings(encoder_noise_counts=2.0), WorldSettings(wheel_slip=0.05)]:
        assert noisy_counts(7, noisy) == noisy_counts(7, noisy)
        assert noisy_counts(7, noisy) != noisy_counts(8, noisy)
        assert noisy_counts(7, noisy) != exact
        np.testing.assert_allclose(noisy_counts(7, noisy), exact, rtol=0.05)


def test_identical_runs_are_bit_identical() -> None:
    def trajectory() -> np.ndarray:
        world = World(ROBOT, pose(0.1, 0.2, 0.3), [Circle(0.9, 0.4, 0.15)], seed=3)
        qs = []
        for left, right in [(0.5, 0.45), (0.2, 0.5), (-0.1, 0.1)]:
            world.command(left, right, [0.3, -0.2, 0.1, 0.5, -0.4])
            qs.append(run(world, 120))
        return np.concatenate(qs)

    np.testing.assert_array_equal(trajectory(), trajectory())


def test_invalid_inputs_are_rejected() -> None:
    world = World(ROBOT, pose(0.0, 0.0, 0.0), [])
    with pytest.raises(ValueError, match="joint_velocities"):
        world.command(0.1, 0.1, [0.0] * 4)
    with pytest.raises(ValueError, match="dt"):
        world.step(0.0)
    with pytest.raises(ValueError, match="outside their limits"):
        World(ROBOT, np.array([0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]), [])


def test_the_arm_penetrating_a_solid_counts_once_per_entry_from_the_kinematics() -> None:
    """The shoulder lowers the arm into a table top in front of the base and raises it again,
    twice: each entry counts once per part that enters (the second as many as the first),
    nothing while the arm stays in, and the count holds when it leaves."""
    table = Plane((0.0, 0.0, 1.0), 0.3, ((0.3, -0.5), (0.9, -0.5), (0.9, 0.5), (0.3, 0.5)))
    start = np.array([0.0, 0.0, 0.0, 0.0, -0.3, -0.3, 0.0, 0.0])  # the arm level, above 0.3 m
    world = World(ROBOT, start, [], INSTANT_WHEELS, solids=[table])
    assert world.arm_penetrations == 0 and not world.arm_penetrating
    entries = []
    for _ in range(2):
        world.command(0.0, 0.0, [0.0, 0.8, 0.0, 0.0, 0.0])  # shoulder down
        run(world, 100)
        assert world.arm_penetrating
        entries.append(world.arm_penetrations)
        world.command(0.0, 0.0, [0.0, -0.8, 0.0, 0.0, 0.0])  # and up again
        run(world, 100)
        assert not world.arm_penetrating
    first = entries[0]
    assert first >= 1 and entries[1] == 2 * first and world.arm_penetrations == 2 * first
