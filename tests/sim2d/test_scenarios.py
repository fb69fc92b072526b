"""The simulated set-ups of section 6.2 (sim2d/scenarios.py) against deploy/sim.yaml's scene."""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.simulator import Simulator
from profiles.deploy_files import ROBOT_FILE
from sim2d.scenarios import (
    ANYWHERE_OBSTACLE,
    ANYWHERE_START,
    BIN_RANGE,
    BLOCKED_START,
    NAMES,
    OBSTACLE_SHIFT,
    START_RANGE,
    TABLE_BIN_RANGE,
    SimScenario,
    scenario,
)
from tests.sim2d.sim_scene import camera, markers, scene
from wbc.geometry.arm_clearance import part_clearances
from wbc.geometry.scenarios import HOME, OBSTACLE, REACH_GOAL, TABLE, TABLE_GOAL, TABLE_START
from wbc.laws.lp_law import LPParams
from wbc.planar import planar_of
from wbc.planning.disc_geometry import segment_clear
from wbc.planning.staging import plan
from wbc.robot import BASE_DOF, MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
SEEDS = range(50)
DEFAULT_BIN = np.array(planar_of(ROBOT.fkm(REACH_GOAL)))


def test_the_default_goal_is_the_dissertations_reach_goal() -> None:
    """x_d = x_2 x_d^2 (eq. 6.3) on the default bin is fkm(REACH_GOAL), up to sign: the goal
    the simulator judges by and a kinematic run of the set-up steers to."""
    setup = scenario("pose", ROBOT)
    goal = scene().goal
    x_d = setup.goal(goal.height_m, goal.offset)
    expected = ROBOT.fkm(REACH_GOAL)
    error = min(np.max(np.abs(x_d - expected)), np.max(np.abs(x_d + expected)))
    assert error < 1e-5, (x_d, expected)


@pytest.mark.parametrize("name", NAMES)
def test_the_default_set_up_starts_at_home(name: str) -> None:
    """Every set-up but 'table' starts with HOME's arm; all but 'anywhere', 'blocked' and
    'table' at HOME's base too; 'table' at TABLE_START."""
    setup = scenario(name, ROBOT)
    assert setup.name == name
    home = TABLE_START.copy() if name == "table" else HOME.copy()
    if name in ("anywhere", "blocked"):
        home[:BASE_DOF] = ANYWHERE_START if name == "anywhere" else BLOCKED_START
    assert np.array_equal(setup.start, home)


def test_the_anywhere_set_up_puts_the_goal_behind_the_robot_past_an_obstacle() -> None:
    setup = scenario("anywhere", ROBOT)
    x, y, phi = setup.start[:BASE_DOF]
    bearing = math.atan2(setup.bin[1] - y, setup.bin[0] - x) - phi
    assert abs(math.remainder(bearing, 2 * math.pi)) > 0.9 * math.pi
    assert setup.task == "pose" and setup.obstacles == (ANYWHERE_OBSTACLE,)


def test_the_blocked_set_up_puts_its_obstacle_on_the_straight_way_clear_of_both_ends() -> None:
    """The obstacle cuts the segment from the start's base to where the staging planner puts
    the base for the bin, by more than the base's body and the LP's margin; both ends stand
    clear of it."""
    setup = scenario("blocked", ROBOT)
    (circle,) = setup.obstacles
    goal = setup.goal(scene().goal.height_m, scene().goal.offset)
    best = plan(ROBOT, np.array(setup.start), goal).candidates[0]
    body = ROBOT.base.body_radius + LPParams().obstacle_margin
    start = np.array(setup.start[:2])
    for end in (best.base[:2], best.staging):
        assert not segment_clear(start, end, [circle], body)
        assert segment_clear(end, end, [circle], body)
    assert segment_clear(start, start, [circle], body)


def test_the_pose_set_up_puts_the_bin_under_the_reach_goal_without_obstacles() -> None:
    setup = scenario("pose", ROBOT)
    assert setup.task == "pose" and setup.obstacles == ()
    assert np.allclose(setup.bin, DEFAULT_BIN, atol=1e-12)


def test_the_position_set_up_has_the_position_task() -> None:
    setup = scenario("position", ROBOT)
    assert setup.task == "position" and setup.obstacles == ()
    assert np.allclose(setup.bin, DEFAULT_BIN, atol=1e-12)


def test_the_obstacle_set_up_shifts_the_bin_past_the_obstacle() -> None:
    setup = scenario("obstacle", ROBOT)
    assert setup.task == "pose"
    assert setup.obstacles == (OBSTACLE,)
    shifted = DEFAULT_BIN + [OBSTACLE_SHIFT[0], OBSTACLE_SHIFT[1], 0.0]
    assert np.allclose(setup.bin, shifted, atol=1e-12)


def test_the_table_set_up_puts_its_goal_over_the_table_edge() -> None:
    """The bin marker lies on the table top under TABLE_GOAL's gripper, and x_d = x_2 x_d^2
    with the set-up's own offset is TABLE_GOAL's pose; the start is clear of the table, and
    so is the goal, by more than the arm rows' margin."""
    setup = scenario("table", ROBOT)
    assert setup.task == "pose" and setup.solids == (TABLE,) and setup.obstacles == ()
    assert setup.goal_height == TABLE.offset
    x_d = setup.goal(setup.goal_height, setup.goal_offset)
    expected = ROBOT.fkm(TABLE_GOAL)
    assert min(np.abs(x_d - expected).max(), np.abs(x_d + expected).max()) < 1e-8
    assert TABLE.clearance(np.array([*setup.bin[:2], TABLE.offset]))[0] == 0.0  # on its top
    for q in (TABLE_START, TABLE_GOAL):
        assert part_clearances(ROBOT, q, (TABLE,)).min() > 0.05


def test_an_unknown_experiment_is_refused() -> None:
    with pytest.raises(ValueError, match="no experiment 'dance'; choose one of pose, position"):
        scenario("dance", ROBOT)


@pytest.mark.parametrize("name", NAMES)
def test_seeded_set_ups_stay_in_their_ranges_and_the_joint_limits(name: str) -> None:
    default = scenario(name, ROBOT)
    for seed in SEEDS:
        setup = scenario(name, ROBOT, seed)
        start, bin_pose = np.array(setup.start), np.array(setup.bin)
        assert np.all(np.abs(start - default.start) <= START_RANGE)
        bins = TABLE_BIN_RANGE if name == "table" else BIN_RANGE
        assert np.all(np.abs(bin_pose - default.bin) <= bins)
        arm = start[BASE_DOF:]
        assert np.all(arm >= ROBOT.q_min[BASE_DOF:]) and np.all(arm <= ROBOT.q_max[BASE_DOF:])
        assert setup.obstacles == default.obstacles and setup.task == default.task


def test_seeds_repeat_and_differ() -> None:
    assert scenario("pose", ROBOT, 3) == scenario("pose", ROBOT, 3)
    draws = {scenario("pose", ROBOT, seed).start for seed in SEEDS}
    bins = {scenario("pose", ROBOT, seed).bin for seed in SEEDS}
    assert len(draws) == len(bins) == len(SEEDS)
    assert scenario("pose", ROBOT, 0).start != tuple(HOME.tolist())


@pytest.mark.parametrize(("name", "seed"), [("pose", None), ("obstacle", None), ("obstacle", 7)])
def test_sim_params_are_the_simulators_typed_values_of_the_set_up(
    name: str, seed: int | None
) -> None:
    """What the simulator's declared parameters take as they are: no vector as text."""
    setup = scenario(name, ROBOT, seed)
    params = setup.sim_params()
    assert set(params) == {"start", "goal_marker", "obstacles"}
    declared = {p.name: p for p in Simulator.params}
    held = {name: declared[name].check(value) for name, value in params.items()}
    assert held["start"] == pytest.approx(setup.start, abs=5e-7)
    assert held["goal_marker"] == pytest.approx(setup.bin, abs=5e-7)
    assert held["obstacles"] == tuple((c.x, c.y, c.radius) for c in setup.obstacles)
    two = SimScenario("obstacle", "pose", tuple(HOME), (1.0, 0.0, 0.0), (OBSTACLE, OBSTACLE))
    assert len(declared["obstacles"].check(two.sim_params()["obstacles"])) == 2


@pytest.mark.parametrize("name", NAMES)
def test_every_marker_is_in_the_image_with_half_a_marker_to_spare(name: str) -> None:
    view = camera()
    assert (view.width, view.height) == (640, 480)
    depth = scene().camera.position[2]
    for seed in (None, *SEEDS):
        for what, x, y, z, size in markers(scenario(name, ROBOT, seed)):
            ((u, v),) = view.project(np.array([[x, y, z]]))
            half = 0.5 * size * view.fx / (depth - z)
            assert half < u < view.width - 1 - half, (name, seed, what, u)
            assert half < v < view.height - 1 - half, (name, seed, what, v)


def test_the_camera_sees_the_world_as_the_check_assumes() -> None:
    """The scene camera's centre pixel is straight below it, world +x to the right."""
    view = camera()
    x, y, _ = scene().camera.position
    centre, right = view.project(np.array([[x, y, 0.0], [x + 0.1, y, 0.0]]))
    assert centre == pytest.approx((view.cx, view.cy))
    assert right[0] > centre[0] and right[1] == pytest.approx(centre[1])
