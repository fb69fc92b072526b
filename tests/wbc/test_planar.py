"""Planar poses (wbc/planar.py), dead reckoning (wbc/base_motion.py) and dq.normalize."""

from __future__ import annotations

import math

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE
from sim2d.world import World, WorldSettings, wheel_distance_per_count
from wbc import dq
from wbc.base_motion import dead_reckoning
from wbc.planar import height_of, planar_of, planar_pose, tilt_of
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
WHEEL_BASE = ROBOT.base.wheel_base


def wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def angle_between(a: float, b: float) -> float:
    return abs(wrap(a - b))


def random_planar(rng: np.random.Generator) -> tuple[float, float, float, float]:
    """x, y in +-3 m, phi in +-10 rad (several turns), z in [0, 1] m."""
    return (*rng.uniform(-3.0, 3.0, 2), rng.uniform(-10.0, 10.0), rng.uniform(0.0, 1.0))


def test_planar_poses_round_trip_with_the_heading_wrapped() -> None:
    rng = np.random.default_rng(0)
    for _ in range(200):
        x, y, phi, z = random_planar(rng)
        pose = planar_pose(x, y, phi, z)
        assert dq.is_unit(pose, tol=1e-12)
        px, py, pphi = planar_of(pose)
        assert (px, py) == pytest.approx((x, y), abs=1e-12)
        assert -math.pi <= pphi <= math.pi
        assert angle_between(pphi, phi) < 1e-12
        assert height_of(pose) == pytest.approx(z, abs=1e-12)
        assert tilt_of(pose) == pytest.approx(0.0, abs=1e-7)


def test_a_planar_pose_matches_its_rotation_and_translation() -> None:
    pose = planar_pose(1.0, -2.0, math.pi / 2, 0.5)
    assert dq.translation(pose) == pytest.approx([0.0, 1.0, -2.0, 0.5], abs=1e-12)
    half = math.sqrt(0.5)
    assert dq.rotation(pose) == pytest.approx([half, 0.0, 0.0, half], abs=1e-12)


def test_a_tilted_pose_still_gives_its_heading_and_its_tilt() -> None:
    """r = Rz(phi) Ry(pitch) Rx(roll): the x axis leaves the plane but keeps its heading."""
    rng = np.random.default_rng(1)
    for _ in range(100):
        x, y, phi, z = random_planar(rng)
        pitch, roll = rng.uniform(-0.3, 0.3, 2)
        yaw_pitch = dq.qmul(
            dq.rotation_quaternion(phi, [0, 0, 1]), dq.rotation_quaternion(pitch, [0, 1, 0])
        )
        r = dq.qmul(yaw_pitch, dq.rotation_quaternion(roll, [1, 0, 0]))
        pose = dq.pose(r, [x, y, z])
        px, py, pphi = planar_of(pose)
        assert (px, py) == pytest.approx((x, y), abs=1e-12)
        assert angle_between(pphi, phi) < 1e-12
        assert height_of(pose) == pytest.approx(z, abs=1e-12)
        # The z axis after Ry(pitch) Rx(roll) makes cos(tilt) = cos(pitch) cos(roll).
        expected = math.acos(math.cos(pitch) * math.cos(roll))
        assert tilt_of(pose) == pytest.approx(expected, abs=1e-7)


def test_the_heading_does_not_depend_on_the_sign_of_the_dual_quaternion() -> None:
    pose = planar_pose(0.4, 0.5, 2.9, 0.1)
    assert planar_of(-pose) == pytest.approx(planar_of(pose), abs=1e-12)


@pytest.mark.parametrize("phi", [0.0, 0.8, -2.5])
def test_a_straight_roll_moves_along_the_heading(phi: float) -> None:
    x, y, new_phi = dead_reckoning(1.0, -0.5, phi, 0.3, 0.3, WHEEL_BASE)
    assert (x, y, new_phi) == pytest.approx(
        (1.0 + 0.3 * math.cos(phi), -0.5 + 0.3 * math.sin(phi), phi), abs=1e-12
    )


def test_a_turn_in_place_only_turns() -> None:
    x, y, phi = dead_reckoning(1.0, -0.5, 0.2, -0.05, 0.05, WHEEL_BASE)
    assert (x, y) == pytest.approx((1.0, -0.5), abs=1e-12)
    assert phi == pytest.approx(0.2 + 0.1 / WHEEL_BASE, abs=1e-12)


def unicycle_arc(
    x: float, y: float, phi: float, ds: float, dphi: float
) -> tuple[float, float, float]:
    """The end of an arc of length ds turning by dphi: radius R = ds / dphi about the centre
    (x - R sin phi, y + R cos phi)."""
    radius = ds / dphi
    cx, cy = x - radius * math.sin(phi), y + radius * math.cos(phi)
    end = phi + dphi
    return cx + radius * math.sin(end), cy - radius * math.cos(end), end


@pytest.mark.parametrize(
    ("d_left", "d_right"), [(0.2, 0.4), (0.5, -0.1), (-0.3, -0.25), (0.0, 0.9), (0.7, 0.69)]
)
def test_an_arc_matches_the_analytic_unicycle(d_left: float, d_right: float) -> None:
    start = (0.3, 0.7, -1.1)
    ds, dphi = 0.5 * (d_left + d_right), (d_right - d_left) / WHEEL_BASE
    got = dead_reckoning(*start, d_left, d_right, WHEEL_BASE)
    assert got == pytest.approx(unicycle_arc(*start, ds, dphi), abs=1e-12)
    radius = ds / dphi
    centre = (start[0] - radius * math.sin(start[2]), start[1] + radius * math.cos(start[2]))
    assert math.hypot(got[0] - centre[0], got[1] - centre[1]) == pytest.approx(abs(radius))


def test_an_arc_in_many_pieces_ends_where_it_does_in_one() -> None:
    pose = (0.0, 0.0, 0.4)
    for _ in range(100):
        pose = dead_reckoning(*pose, 0.002, 0.005, WHEEL_BASE)
    assert pose == pytest.approx(dead_reckoning(0.0, 0.0, 0.4, 0.2, 0.5, WHEEL_BASE), abs=1e-12)


@pytest.mark.parametrize(("left", "right"), [(0.1, 0.2), (0.3, 0.15), (-0.12, -0.2)])
def test_dead_reckoning_of_the_world_encoders_follows_the_true_base(
    left: float, right: float
) -> None:
    """5 s of an arc, noise 0: each step's count increments through dead_reckoning.

    Counts are the floor of the rolled distance, so the odometry lags the truth by less than one
    count per wheel, 0.44 mm and 0.11 deg, plus the heading error that lag carries along.
    """
    q0 = np.array([0.3, -0.2, 0.4, 0.0, 0.0, 0.0, 0.0, 0.0])
    world = World(ROBOT, q0, [], WorldSettings(), seed=0)
    per_count = wheel_distance_per_count(ROBOT.base, world.settings.counts_per_turn)
    world.command(left, right, np.zeros(ROBOT.arm_dof))
    x, y, phi = q0[:3]
    before = world.encoder_counts
    for _ in range(500):
        world.step(0.01)
        counts = world.encoder_counts
        assert all(isinstance(c, int) for c in counts)
        d_left, d_right = ((c - b) * per_count for c, b in zip(counts, before, strict=True))
        x, y, phi = dead_reckoning(x, y, phi, d_left, d_right, WHEEL_BASE)
        before = counts
    truth = world.q
    assert world.time_s == pytest.approx(5.0)
    assert math.hypot(truth[0] - q0[0], truth[1] - q0[1]) > 0.4  # it did drive
    assert math.hypot(x - truth[0], y - truth[1]) < 2e-3
    assert abs(phi - truth[2]) < math.radians(0.2)


def test_normalize_makes_a_perturbed_dual_quaternion_unit() -> None:
    rng = np.random.default_rng(4)
    for _ in range(100):
        pose = planar_pose(*random_planar(rng))
        perturbed = pose * rng.uniform(0.5, 2.0) + rng.normal(scale=0.05, size=8)
        unit = dq.normalize(perturbed)
        assert dq.is_unit(unit, tol=1e-12)
        assert not dq.is_unit(perturbed)
        assert np.allclose(unit, pose, atol=0.3)  # near the pose it came from, same sign


def test_normalize_leaves_a_unit_dual_quaternion_unchanged() -> None:
    rng = np.random.default_rng(5)
    for _ in range(100):
        pose = dq.pose(
            dq.rotation_quaternion(rng.uniform(-math.pi, math.pi), rng.normal(size=3)),
            rng.uniform(-2.0, 2.0, 3),
        )
        assert np.allclose(dq.normalize(pose), pose, rtol=0.0, atol=1e-12)
        assert np.allclose(dq.normalize(3.0 * pose), pose, rtol=0.0, atol=1e-12)
