"""The LP constraints (wbc/laws/constraints/): their rows on hand-built step contexts (chapter
5)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from profiles.deploy_files import ROBOT_FILE
from wbc.geometry.obstacles import Circle
from wbc.laws.constraints.base import LinearRows, OneNormBound, VelocityBounds
from wbc.laws.constraints.error_bound import ErrorBound
from wbc.laws.constraints.joint_limits import JointLimits
from wbc.laws.constraints.nonholonomic import Nonholonomic
from wbc.laws.constraints.obstacle_border import BorderObstacle
from wbc.laws.constraints.obstacle_conservative import ConservativeObstacle
from wbc.laws.constraints.obstacle_vector_field import VectorFieldObstacle
from wbc.laws.step_context import StepContext
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
NO_DEADLINE = settings(deadline=None)
finite = st.floats(-5.0, 5.0)
angles = st.floats(-math.pi, math.pi)


def context(
    q: np.ndarray | None = None,
    error: np.ndarray | None = None,
    error_rate: np.ndarray | None = None,
    goal_xy: tuple[float, float] = (0.0, 0.0),
    obstacles: tuple[Circle, ...] = (),
) -> StepContext:
    return StepContext(
        robot=ROBOT,
        q=np.zeros(ROBOT.dof) if q is None else np.asarray(q, float),
        error=np.zeros(8) if error is None else np.asarray(error, float),
        error_rate=np.zeros(8) if error_rate is None else np.asarray(error_rate, float),
        goal_xy=np.asarray(goal_xy, float),
        obstacles=obstacles,
    )


def base_at(x: float, y: float, phi: float = 0.0) -> np.ndarray:
    return np.array([x, y, phi, 0.0, 0.0, 0.0, 0.0, 0.0])


# --- Nonholonomic (5.11, 5.12) ----------------------------------------------------------------


@NO_DEADLINE
@given(angles, finite, finite)
def test_nonholonomic_row_is_sin_minus_cos(phi: float, x: float, y: float) -> None:
    rows = Nonholonomic().rows(context(base_at(x, y, phi)))
    assert isinstance(rows, LinearRows) and rows.engaged
    expected = np.zeros((1, ROBOT.dof))
    expected[0, :2] = math.sin(phi), -math.cos(phi)
    np.testing.assert_array_equal(rows.matrix, expected)
    np.testing.assert_array_equal(rows.lower, [0.0])
    np.testing.assert_array_equal(rows.upper, [0.0])


@NO_DEADLINE
@given(angles, finite, finite, st.lists(finite, min_size=5, max_size=5))
def test_unicycle_motion_satisfies_the_nonholonomic_row(
    phi: float, forward: float, turn: float, arm: list[float]
) -> None:
    rows = Nonholonomic().rows(context(base_at(0.3, -0.2, phi)))
    u = np.array([forward * math.cos(phi), forward * math.sin(phi), turn, *arm])
    assert abs((rows.matrix @ u)[0]) <= 1e-12


@NO_DEADLINE
@given(angles, st.floats(0.01, 5.0))
def test_sideways_motion_violates_the_nonholonomic_row(phi: float, speed: float) -> None:
    rows = Nonholonomic().rows(context(base_at(0.0, 0.0, phi)))
    u = np.zeros(ROBOT.dof)
    u[:2] = -speed * math.sin(phi), speed * math.cos(phi)
    assert (rows.matrix @ u)[0] == pytest.approx(-speed)


# --- Joint limits (5.13-5.18) -----------------------------------------------------------------


def arm_inside(safety_factor: float) -> st.SearchStrategy[np.ndarray]:
    """Arm configurations inside the shrunk box b_l [q-, q+]."""
    low, high = safety_factor * ROBOT.q_min[3:], safety_factor * ROBOT.q_max[3:]
    return st.tuples(*[st.floats(lo, hi) for lo, hi in zip(low, high, strict=True)]).map(np.array)


@NO_DEADLINE
@given(
    st.floats(0.1, 10.0),
    st.floats(0.5, 1.0),
    st.data(),
    st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)),
)
def test_joint_limit_bounds_are_equation_5_15(
    gain: float, safety_factor: float, data: st.DataObject, base: tuple[float, float, float]
) -> None:
    arm = data.draw(arm_inside(safety_factor))
    q = np.concatenate((base, arm))
    bounds = JointLimits(gain, safety_factor).rows(context(q))
    assert isinstance(bounds, VelocityBounds)
    speed = ROBOT.velocity_max
    lower = np.maximum(-speed[3:], gain * (safety_factor * ROBOT.q_min[3:] - arm))
    upper = np.minimum(speed[3:], gain * (safety_factor * ROBOT.q_max[3:] - arm))
    np.testing.assert_allclose(bounds.lower[3:], lower, rtol=0, atol=1e-12)
    np.testing.assert_allclose(bounds.upper[3:], upper, rtol=0, atol=1e-12)
    # The base has no position limits: only its velocity bounds remain, wherever it is.
    np.testing.assert_array_equal(bounds.lower[:3], -speed[:3])
    np.testing.assert_array_equal(bounds.upper[:3], speed[:3])


def test_joint_limit_bound_shrinks_near_the_limit() -> None:
    """k (b_l q+ - q) takes over from the speed limit as the joint nears b_l q+."""
    q = np.zeros(ROBOT.dof)
    q[4] = 0.9 * ROBOT.q_max[4] - 0.1
    bounds = JointLimits(gain=2.0, safety_factor=0.9).rows(context(q))
    assert bounds.upper[4] == pytest.approx(0.2)
    assert bounds.lower[4] == -ROBOT.velocity_max[4]
    q[4] = 0.9 * ROBOT.q_max[4]
    assert JointLimits(gain=2.0, safety_factor=0.9).rows(context(q)).upper[4] == pytest.approx(0)


@NO_DEADLINE
@given(st.integers(3, 7), st.floats(1e-6, 3.0), st.floats(0.1, 10.0), st.floats(0.5, 1.0))
def test_joint_beyond_the_upper_margin_must_move_back(
    joint: int, overshoot: float, gain: float, safety_factor: float
) -> None:
    q = np.zeros(ROBOT.dof)
    q[joint] = safety_factor * ROBOT.q_max[joint] + overshoot
    bounds = JointLimits(gain, safety_factor).rows(context(q))
    speed = ROBOT.velocity_max[joint]
    assert bounds.upper[joint] <= 0.0
    assert -speed <= bounds.lower[joint] <= bounds.upper[joint]


@NO_DEADLINE
@given(st.integers(3, 7), st.floats(1e-6, 3.0), st.floats(0.1, 10.0), st.floats(0.5, 1.0))
def test_joint_beyond_the_lower_margin_must_move_back(
    joint: int, overshoot: float, gain: float, safety_factor: float
) -> None:
    q = np.zeros(ROBOT.dof)
    q[joint] = safety_factor * ROBOT.q_min[joint] - overshoot
    bounds = JointLimits(gain, safety_factor).rows(context(q))
    speed = ROBOT.velocity_max[joint]
    assert bounds.lower[joint] >= 0.0
    assert bounds.lower[joint] <= bounds.upper[joint] <= speed


@NO_DEADLINE
@given(st.lists(st.floats(-10.0, 10.0), min_size=8, max_size=8), st.floats(0.1, 10.0))
def test_joint_limit_bounds_are_ordered_and_within_speed(q: list[float], gain: float) -> None:
    bounds = JointLimits(gain, 0.9).rows(context(np.array(q)))
    speed = ROBOT.velocity_max
    assert np.all(bounds.lower <= bounds.upper)
    assert np.all(-speed <= bounds.lower) and np.all(bounds.upper <= speed)
    assert np.all(np.isfinite(bounds.lower)) and np.all(np.isfinite(bounds.upper))


@pytest.mark.parametrize(("gain", "safety_factor"), [(0.0, 0.9), (-1.0, 0.9), (1, 0), (1, 1.1)])
def test_joint_limits_reject_bad_parameters(gain: float, safety_factor: float) -> None:
    with pytest.raises(ValueError):
        JointLimits(gain, safety_factor)


# --- Error bound (5.7, 5.10) ------------------------------------------------------------------


@NO_DEADLINE
@given(
    st.floats(0.01, 100.0),
    st.lists(finite, min_size=8, max_size=8),
    st.lists(finite, min_size=8, max_size=8),
)
def test_error_bound_limit(beta: float, error: list[float], error_rate: list[float]) -> None:
    step = context(error=np.array(error), error_rate=np.array(error_rate))
    derivative = ErrorBound(beta).rows(step)
    assert isinstance(derivative, OneNormBound)
    assert derivative.limit == pytest.approx(beta * sum(abs(v) for v in error_rate))
    assert derivative.name == "error_derivative_bound"
    original = ErrorBound(beta, mode="error").rows(step)
    assert original.limit == pytest.approx(beta * sum(abs(v) for v in error))
    assert original.name == "error_bound"


def test_error_bound_vanishes_when_the_end_effector_stalls() -> None:
    """e != 0 but e' = 0: the derivative form (5.10) stops the joints, the original (5.7) not."""
    step = context(error=np.full(8, 0.1), error_rate=np.zeros(8))
    assert ErrorBound(2.0).rows(step).limit == 0.0
    assert ErrorBound(2.0, mode="error").rows(step).limit == pytest.approx(1.6)


@pytest.mark.parametrize(("beta", "mode"), [(0.0, "derivative"), (-1.0, "error"), (1.0, "both")])
def test_error_bound_rejects_bad_parameters(beta: float, mode: str) -> None:
    with pytest.raises(ValueError):
        ErrorBound(beta, mode)  # type: ignore[arg-type]


# --- Conservative obstacle (5.19) -------------------------------------------------------------


def test_conservative_obstacle_is_unbounded_without_obstacles() -> None:
    bounds = ConservativeObstacle().rows(context(base_at(1.0, 2.0)))
    assert isinstance(bounds, VelocityBounds)
    assert np.all(bounds.lower == -np.inf) and np.all(bounds.upper == np.inf)


@pytest.mark.parametrize("gain", [0.5, 1.0, 3.0])
def test_conservative_obstacle_bound_shrinks_to_zero_at_the_disc(gain: float) -> None:
    constraint = ConservativeObstacle(gain=gain, margin=0.05)
    obstacle = Circle(2.0, 0.0, 0.3)
    border = 2.0 - (0.3 + ROBOT.base.body_radius + 0.05)
    previous = np.inf
    for x in (border - 1.0, border - 0.5, border - 0.1, border - 0.01):
        bounds = constraint.rows(context(base_at(x, 0.0), obstacles=(obstacle,)))
        expected = gain * (border - x)
        np.testing.assert_allclose(bounds.upper[:2], expected, rtol=1e-12)
        np.testing.assert_allclose(bounds.lower[:2], -expected, rtol=1e-12)
        assert np.all(bounds.upper[2:] == np.inf) and np.all(bounds.lower[2:] == -np.inf)
        assert expected < previous
        previous = expected
    at_border = constraint.rows(context(base_at(border, 0.0), obstacles=(obstacle,)))
    np.testing.assert_allclose(at_border.upper[:2], [0.0, 0.0], rtol=0, atol=1e-12)
    for x in (border + 0.1, 2.0):
        bounds = constraint.rows(context(base_at(x, 0.0), obstacles=(obstacle,)))
        np.testing.assert_array_equal(bounds.upper[:2], [0.0, 0.0])
        np.testing.assert_array_equal(bounds.lower[:2], [0.0, 0.0])


def test_conservative_obstacle_takes_the_nearest_obstacle() -> None:
    near, far = Circle(1.0, 0.0, 0.2), Circle(0.0, -3.0, 0.2)
    bounds = ConservativeObstacle(gain=1.0, margin=0.0).rows(
        context(base_at(0.0, 0.0), obstacles=(far, near))
    )
    expected = 1.0 - 0.2 - ROBOT.base.body_radius
    np.testing.assert_allclose(bounds.upper[:2], expected, rtol=1e-12)


# --- Border obstacle (5.21-5.28) --------------------------------------------------------------

OBSTACLE = Circle(1.0, 0.5, 0.25)
GAIN, MARGIN = 2.0, 0.05
EXTENDED_RADIUS = OBSTACLE.radius + ROBOT.base.body_radius + MARGIN
CENTRE = np.array([OBSTACLE.x, OBSTACLE.y])


def border_rows(
    x: float, y: float, goal: tuple[float, float], phi: float = 0.0, lookahead: float = 0.0
) -> LinearRows:
    step = context(base_at(x, y, phi), goal_xy=goal, obstacles=(OBSTACLE,))
    return BorderObstacle(gain=GAIN, margin=MARGIN, lookahead=lookahead).rows(step)


@pytest.mark.parametrize("lookahead", [0.0, 0.1])
def test_border_obstacle_is_off_outside_the_extended_disc(lookahead: float) -> None:
    """f <= 0: the row is all zeros and not engaged, even with the obstacle on the way."""
    x = OBSTACLE.x - EXTENDED_RADIUS - 2.0 * lookahead - 0.01  # p = axle + lookahead along x
    rows = border_rows(x, OBSTACLE.y, (3.0, OBSTACLE.y), lookahead=lookahead)
    assert not rows.engaged
    assert rows.matrix.shape == (1, ROBOT.dof)
    assert not np.any(rows.matrix) and not np.any(rows.lower) and not np.any(rows.upper)


@pytest.mark.parametrize("lookahead", [0.0, 0.1])
def test_border_obstacle_is_off_when_the_obstacle_is_not_towards_the_goal(lookahead: float) -> None:
    """Inside the disc (f > 0) but the goal is nearer to the base than to the obstacle: h <= 0."""
    x, y = OBSTACLE.x - 0.5 * EXTENDED_RADIUS - lookahead, OBSTACLE.y
    rows = border_rows(x, y, (x - 2.0, y), lookahead=lookahead)
    assert not rows.engaged
    assert not np.any(rows.matrix) and not np.any(rows.lower)


def test_border_obstacle_has_one_row_per_obstacle() -> None:
    far = Circle(-5.0, -5.0, 0.3)
    step = context(base_at(0.6, 0.5), goal_xy=(3.0, 0.5), obstacles=(far, OBSTACLE, far))
    rows = BorderObstacle(gain=GAIN, margin=MARGIN, lookahead=0.0).rows(step)
    assert rows.matrix.shape == (3, ROBOT.dof) and rows.engaged
    assert not np.any(rows.matrix[[0, 2]]) and np.any(rows.matrix[1])


inside_offsets = st.tuples(st.floats(0.05, 0.99), st.floats(-math.pi, math.pi))


@NO_DEADLINE
@given(inside_offsets, st.floats(0.1, 3.0), st.lists(finite, min_size=7, max_size=7))
def test_engaged_border_obstacle_pushes_the_base_outward(
    offset: tuple[float, float], beyond: float, free: list[float]
) -> None:
    """Inside, with the obstacle between base and goal, any u on the row moves the base out.

    With no look-ahead the row is -2 (q_xy - c)' u_xy = -gain f (5.27), so the radial velocity
    of the base is gain f / (2 ||q_xy - c||), whatever the tangential velocity and the joints.
    """
    fraction, bearing = offset
    direction = np.array([math.cos(bearing), math.sin(bearing)])
    base = CENTRE + fraction * EXTENDED_RADIUS * direction
    goal = CENTRE - beyond * direction  # straight through the obstacle from the base
    rows = border_rows(base[0], base[1], tuple(goal))
    assert rows.engaged
    offset_xy = base - CENTRE
    distance = float(np.linalg.norm(offset_xy))
    f = EXTENDED_RADIUS**2 - distance**2
    expected_row = np.zeros(ROBOT.dof)
    expected_row[:2] = -2.0 * offset_xy
    np.testing.assert_allclose(rows.matrix[0], expected_row, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rows.lower, [-GAIN * f], rtol=1e-12)
    np.testing.assert_array_equal(rows.lower, rows.upper)
    # Any u on the row: a particular solution plus a free tangential part and free other joints.
    radial = offset_xy / distance
    tangent = np.array([-radial[1], radial[0]])
    u = np.zeros(ROBOT.dof)
    u[:2] = rows.lower[0] / (-2.0 * distance) * radial + free[0] * tangent
    u[2:] = free[1:]
    assert rows.matrix[0] @ u == pytest.approx(rows.lower[0], rel=1e-9, abs=1e-12)
    radial_velocity = float(radial @ u[:2])
    assert radial_velocity == pytest.approx(GAIN * f / (2.0 * distance), rel=1e-9)
    assert radial_velocity > 0.0


@NO_DEADLINE
@given(
    inside_offsets,
    angles,
    st.floats(0.01, 0.3),
    st.floats(0.1, 3.0),
    st.lists(finite, min_size=2, max_size=2),
)
def test_engaged_border_obstacle_with_lookahead_pushes_the_point_ahead_outward(
    offset: tuple[float, float],
    phi: float,
    lookahead: float,
    beyond: float,
    free: list[float],
) -> None:
    """The row holds exactly for the base motions whose point p = axle + d (cos phi, sin phi)

    moves outward at gain f / (2 ||p - c||), f = (R + d)^2 - ||p - c||^2, p' taken from
    (x', y', phi') as p' = (x' - d sin(phi) phi', y' + d cos(phi) phi').
    """
    fraction, bearing = offset
    direction = np.array([math.cos(bearing), math.sin(bearing)])
    heading = np.array([math.cos(phi), math.sin(phi)])
    radius = EXTENDED_RADIUS + lookahead
    point = CENTRE + fraction * radius * direction
    axle = point - lookahead * heading
    goal = CENTRE - beyond * direction
    rows = border_rows(axle[0], axle[1], tuple(goal), phi=phi, lookahead=lookahead)
    assert rows.engaged
    distance = fraction * radius
    f = radius**2 - distance**2
    np.testing.assert_allclose(rows.lower, [-GAIN * f], rtol=1e-9)
    tangent = np.array([-direction[1], direction[0]])
    turn, slide = free
    point_velocity = GAIN * f / (2.0 * distance) * direction + slide * tangent
    u = np.zeros(ROBOT.dof)
    u[0] = point_velocity[0] + lookahead * math.sin(phi) * turn
    u[1] = point_velocity[1] - lookahead * math.cos(phi) * turn
    u[2] = turn
    assert rows.matrix[0] @ u == pytest.approx(rows.lower[0], rel=1e-9, abs=1e-9)
    # Any other radial speed of p breaks the row.
    u[:2] += 0.01 * direction
    assert rows.matrix[0] @ u != pytest.approx(rows.lower[0], rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("constraint", [BorderObstacle, ConservativeObstacle])
@pytest.mark.parametrize(("gain", "margin"), [(0.0, 0.05), (-1.0, 0.05), (1.0, -0.01)])
def test_obstacle_constraints_reject_bad_parameters(
    constraint: type, gain: float, margin: float
) -> None:
    with pytest.raises(ValueError):
        constraint(gain=gain, margin=margin)


def test_border_obstacle_rejects_a_negative_lookahead() -> None:
    with pytest.raises(ValueError):
        BorderObstacle(lookahead=-0.1)


# --- The vector-field inequality (Marinho, Adorno et al. 2019) --------------------------------


def point_distance(q: np.ndarray, obstacle: Circle, margin: float, lookahead: float) -> float:
    """d: the point lookahead ahead of the axle to the circle of R_obs + body + margin + d."""
    px, py = q[0] + lookahead * math.cos(q[2]), q[1] + lookahead * math.sin(q[2])
    radius = obstacle.radius + ROBOT.base.body_radius + margin + lookahead
    return math.hypot(px - obstacle.x, py - obstacle.y) - radius


@NO_DEADLINE
@given(
    st.floats(-1.5, -0.7),
    st.floats(-0.5, 0.5),
    angles,
    st.floats(0.0, 0.2),
    st.lists(st.floats(-1.0, 1.0), min_size=8, max_size=8),
)
def test_the_vector_field_row_is_minus_the_rate_of_the_distance(
    x: float, y: float, phi: float, lookahead: float, u: list[float]
) -> None:
    """-n . p'(u) = -d'(u): checked against a central difference of d along u."""
    obstacle = Circle(0.0, 0.0, 0.1)
    q = base_at(x, y, phi)
    rows = VectorFieldObstacle(2.0, 0.05, lookahead).rows(context(q, obstacles=(obstacle,)))
    step = 1e-6
    direction = np.array(u)
    rate = (
        point_distance(q + step * direction, obstacle, 0.05, lookahead)
        - point_distance(q - step * direction, obstacle, 0.05, lookahead)
    ) / (2 * step)
    assert (rows.matrix @ direction)[0] == pytest.approx(-rate, abs=1e-6)
    assert rows.upper[0] == pytest.approx(2.0 * point_distance(q, obstacle, 0.05, lookahead))
    assert rows.lower[0] == -np.inf and rows.engaged  # an inequality: u = 0 always meets it


def test_the_vector_field_inequality_lets_the_base_approach_only_exponentially():
    """Driven straight at the obstacle, the point slows as d shrinks and never reaches it:
    d_k >= d_0 (1 - eta_d dt)^k at steps of dt (d(t) >= d(0) exp(-eta_d t) in continuous time)."""
    obstacle = Circle(1.0, 0.0, 0.1)
    law = VectorFieldObstacle(2.0, 0.05, 0.1)
    q = base_at(0.0, 0.0, 0.0)
    start = point_distance(q, obstacle, 0.05, 0.1)
    for k in range(1, 400):
        rows = law.rows(context(q, obstacles=(obstacle,)))
        forward = min(0.2, rows.upper[0] / -rows.matrix[0, 0])  # as fast as the row allows
        q = q + 0.02 * np.array([forward, 0, 0, 0, 0, 0, 0, 0])
        distance = point_distance(q, obstacle, 0.05, 0.1)
        assert distance >= start * (1.0 - 2.0 * 0.02) ** k - 1e-12 and distance > 0.0
