"""The rows that keep the robot's collision parts clear of obstacles in 3-D
(wbc/laws/constraints/arm_obstacles.py), and the reach over a table's edge in the kinematic loop."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE
from studies.gain_sets import TABLE_PARAMS, WITHOUT_ARM_ROWS
from tests.wbc.wbc_scenarios import configurations, context
from wbc.geometry.arm_clearance import PenetrationCount, part_clearances
from wbc.geometry.obstacles import Circle
from wbc.geometry.obstacles3d import Cylinder, Plane
from wbc.geometry.scenarios import DT, HOME, REACH_GOAL, TABLE, TABLE_GOAL, TABLE_START
from wbc.laws.constraints.arm_obstacles import ArmObstacles
from wbc.laws.kinematic_run import integrate
from wbc.laws.lp_law import LPLaw, LPParams, default_constraints
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
NEAR_LOW, NEAR_HIGH = (-0.2, -0.2, -0.5), (0.3, 0.2, 0.5)
"""The base near the origin, facing within 0.5 rad of x."""
POLE = Cylinder(0.45, 0.05, 0.04, 0.5, "pole")
WALL = Plane((-1.0, 0.0, 0.0), -0.7, name="wall")  # the solid is x > 0.7
TALL_POLE = Cylinder(0.4, -0.2, 0.05, name="tall pole")
SOLIDS = (TABLE, POLE, WALL, TALL_POLE)
GAIN, MARGIN = 2.0, 0.03


def test_no_solids_no_rows_and_the_rows_are_on_by_default() -> None:
    rows = ArmObstacles().rows(context(ROBOT, TABLE_START, ()))
    assert rows.matrix.shape == (0, ROBOT.dof) and not rows.engaged
    assert any(isinstance(c, ArmObstacles) for c in default_constraints(LPParams()))
    assert not any(
        isinstance(c, ArmObstacles) for c in default_constraints(LPParams(arm_obstacles=False))
    )


def test_one_row_per_pair_whatever_the_state() -> None:
    """Every point against every solid, every segment against every solid with lines (the
    table's edges, the poles' axes; not the wall): the LP keeps its shape from step to step."""
    points, segments = len(ROBOT.collision.points), len(ROBOT.collision.segments)
    expected = 4 * points + 3 * segments
    for q in configurations(ROBOT, 30, 1, NEAR_LOW, NEAR_HIGH):
        rows = ArmObstacles(GAIN, MARGIN).rows(context(ROBOT, q, SOLIDS))
        assert rows.matrix.shape == (expected, ROBOT.dof) and rows.engaged
        assert np.all(np.isneginf(rows.lower))


def test_zero_velocity_always_meets_the_rows() -> None:
    """u = 0 is feasible in every configuration, inside an obstacle too (5.8's argument)."""
    for q in configurations(ROBOT, 200, 2, NEAR_LOW, NEAR_HIGH):
        rows = ArmObstacles(GAIN, MARGIN).rows(context(ROBOT, q, SOLIDS))
        assert np.all(rows.upper >= 0.0)


def bound_rate(q: np.ndarray, u: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """d/dt of each row's bound eta (d - d_safe) along u, by central differences."""
    plus = ArmObstacles(GAIN, MARGIN).rows(context(ROBOT, q + step * u, SOLIDS)).upper
    minus = ArmObstacles(GAIN, MARGIN).rows(context(ROBOT, q - step * u, SOLIDS)).upper
    with np.errstate(invalid="ignore"):  # inf - inf: a segment's row off on both sides
        return (plus - minus) / (2.0 * step)


def test_each_row_is_minus_the_rate_of_its_distance() -> None:
    """Row i is -J_d: with eta (d - d_safe) its bound, -row_i u = d'(u), so the row holds iff
    d' >= -eta (d - d_safe) (the VFI). Checked where each bound is positive and its face or
    line stays the one chosen (the rate is then finite)."""
    rng = np.random.default_rng(3)
    checked = 0
    for q in configurations(ROBOT, 60, 4, NEAR_LOW, NEAR_HIGH):
        rows = ArmObstacles(GAIN, MARGIN).rows(context(ROBOT, q, SOLIDS))
        u = rng.uniform(-ROBOT.velocity_max, ROBOT.velocity_max)
        rate = bound_rate(q, u)
        live = np.isfinite(rows.upper) & (rows.upper > 1e-3) & np.isfinite(rate)
        live &= np.abs(rate) < 1e3  # a switch of face between q - eps u and q + eps u
        np.testing.assert_allclose(
            -(rows.matrix @ u)[live] * GAIN, rate[live], rtol=1e-5, atol=1e-7
        )
        checked += int(live.sum())
    assert checked > 500


def test_segment_rows_engage_across_a_table_edge_and_a_pole() -> None:
    """The forearm held over the table's near rim, and across a pole's axis: the line row is on
    there, and off (0 u <= inf) where the segment faces no edge."""
    over_the_rim = np.array([0.33, 0.0, 0.0, 0.0, -0.6, 0.2, -1.0, 0.4])
    rows = ArmObstacles(GAIN, MARGIN).rows(context(ROBOT, over_the_rim, (TABLE,)))
    forearm = len(ROBOT.collision.points)
    assert np.isfinite(rows.upper[forearm]) and np.any(rows.matrix[forearm])
    far = np.array([-1.0, 0.0, np.pi, 0.0, -0.2, 0.2, 0.0, 0.0])  # turned away from the table
    rows = ArmObstacles(GAIN, MARGIN).rows(context(ROBOT, far, (TABLE,)))
    assert np.isinf(rows.upper[forearm]) and not np.any(rows.matrix[forearm])


def test_a_point_is_held_by_the_feature_nearest_it() -> None:
    """The gripper above the table top is held by the top (its row lifts it: -J_t's z row),
    the base beside the near edge by the edge (its row pushes it back along -x)."""
    parts = ROBOT.collision.names
    rows = ArmObstacles(GAIN, MARGIN).rows(context(ROBOT, TABLE_GOAL, (TABLE,)))
    base, gripper = parts.index("base"), parts.index("gripper")
    np.testing.assert_allclose(rows.matrix[base], [1.0, 0, 0, 0, 0, 0, 0, 0], atol=1e-12)
    translation = ROBOT.translation_jacobian(TABLE_GOAL)
    np.testing.assert_allclose(rows.matrix[gripper], -translation[3], atol=1e-12)
    clearance = part_clearances(ROBOT, TABLE_GOAL, (TABLE,))[:, 0]
    radius = ROBOT.collision.points[gripper].radius
    assert rows.upper[gripper] == pytest.approx(
        GAIN * (clearance[gripper] + radius - radius - MARGIN)
    )


def least_clearances(configurations: list[np.ndarray], solids: tuple) -> tuple[float, int]:
    count, least = PenetrationCount(), np.inf
    for q in configurations:
        clearances = part_clearances(ROBOT, q, solids)
        count.update(clearances)
        least = min(least, float(clearances.min()))
    return least, count.count


def test_the_arm_reaches_over_the_table_edge_without_touching_it() -> None:
    """Kinematic closed loop, 50 Hz: from TABLE_START the LP reaches TABLE_GOAL's pose with
    every part at least the margin off the table (less the step's first-order slack); blind to
    the table, its hand cuts through the edge on the way."""
    task = PoseTask(ROBOT.fkm(TABLE_GOAL))
    guarded = integrate(LPLaw(ROBOT, TABLE_PARAMS), TABLE_START, task, DT, 1500, obstacles=(TABLE,))
    assert guarded.converged
    least, penetrations = least_clearances(guarded.configurations, (TABLE,))
    assert penetrations == 0 and least > TABLE_PARAMS.arm_obstacle_margin - 0.005
    blind = integrate(
        LPLaw(ROBOT, WITHOUT_ARM_ROWS), TABLE_START, task, DT, 1500, obstacles=(TABLE,)
    )
    least, penetrations = least_clearances(blind.configurations, (TABLE,))
    assert blind.converged and penetrations > 0 and least < -0.01


def test_the_rows_hold_the_gripper_off_a_pole_it_is_driven_into() -> None:
    """A pose goal whose gripper lies inside a tall pole: the LP stops the hand at the pole's
    radius plus the margin and never comes closer than d_safe e^{-eta t} would allow."""
    pole = Cylinder(0.42, 0.06, 0.04, name="pole")
    task = PoseTask(ROBOT.fkm(np.array([0.0, 0.0, 0.0, 0.0, -0.2, 0.2, 0.0, 0.5])))
    start = np.array([0.0, 0.0, 0.0, 0.6, -0.2, 0.2, 0.0, 0.5])
    run = integrate(
        LPLaw(ROBOT, replace(TABLE_PARAMS, arm_obstacle_margin=MARGIN)),
        start,
        task,
        DT,
        600,
        obstacles=(pole, Circle(2.0, 2.0, 0.1)),
    )
    least, penetrations = least_clearances(run.configurations, (pole,))
    assert penetrations == 0 and least > MARGIN - 0.005
    assert not run.converged  # the goal lies inside the pole


def test_without_solids_the_constraint_changes_nothing() -> None:
    """The pose experiment's run with the constraint in the law and no solid is bit-identical
    to the run without it: the commands of every run before this feature stay as they were."""
    task = PoseTask(ROBOT.fkm(REACH_GOAL))
    on = integrate(LPLaw(ROBOT, LPParams()), HOME, task, DT, 300, obstacles=(Circle(2, 2, 0.1),))
    off = integrate(
        LPLaw(ROBOT, LPParams(arm_obstacles=False)),
        HOME,
        task,
        DT,
        300,
        obstacles=(Circle(2, 2, 0.1),),
    )
    assert np.array_equal(on.velocities(), off.velocities())
