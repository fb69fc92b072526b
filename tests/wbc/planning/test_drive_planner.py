"""The base's way round circles (wbc/planning/drive_planner.py): clear of every grown disc, no
longer than the shortest way, and a reason where there is none."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wbc.geometry.obstacles import Circle
from wbc.planning.drive_planner import WayPlanner, plan_way

CLEARANCE = 0.215
"""The base's body radius and the LP's margin."""


def polyline(way) -> list[np.ndarray]:
    return [way.start, *way.waypoints]


def distance_to_segment(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    direction = b - a
    t = np.clip((point - a) @ direction / (direction @ direction), 0.0, 1.0)
    return float(np.hypot(*(a + t * direction - point)))


def assert_clear(way, obstacles, grown: float) -> None:
    points = polyline(way)
    for c in obstacles:
        centre = np.array([c.x, c.y])
        for a, b in zip(points, points[1:], strict=False):
            assert distance_to_segment(centre, a, b) >= c.radius + grown - 1e-9


def test_the_way_round_one_circle_is_the_tangent_arc_tangent_path() -> None:
    """From (-1, 0) to (1, 0) round a disc of radius R at the origin the shortest way is two
    tangents of sqrt(1 - R^2) and the arc between their touching points, R (pi - 2 acos R)."""
    circle = Circle(0.0, 0.0, 0.1)
    grown = circle.radius + CLEARANCE + 0.1
    way = plan_way(np.array([-1.0, 0.0]), np.array([1.0, 0.0]), [circle], CLEARANCE, 0.1)
    exact = 2.0 * math.sqrt(1.0 - grown**2) + grown * (math.pi - 2.0 * math.acos(grown))
    assert way.found
    assert way.length == pytest.approx(exact, rel=1e-12)
    assert len(way.arcs) == 1 and way.turning == pytest.approx(math.pi - 2 * math.acos(grown))
    assert_clear(way, [circle], CLEARANCE + 0.1)
    legs = sum(np.hypot(*(b - a)) for a, b in zip(polyline(way), polyline(way)[1:], strict=False))
    corner = 1.0 / math.cos(way.turning / 4.0)  # two corners for an arc of 0.82 rad
    assert exact <= legs <= exact * corner
    np.testing.assert_allclose(way.waypoints[-1], [1.0, 0.0])


def test_an_open_way_is_straight_and_a_way_between_circles_takes_the_gap() -> None:
    straight = plan_way(
        np.array([0.0, 0.0]), np.array([2.0, 0.0]), [Circle(1.0, 1.0, 0.1)], CLEARANCE
    )
    assert straight.length == pytest.approx(2.0) and not straight.arcs
    # Two posts 1.2 m apart across the straight way, a gap wide enough between them: the way
    # goes through the gap, shorter than round either post.
    posts = [Circle(1.0, 0.6, 0.1), Circle(1.0, -0.6, 0.1)]
    gap = plan_way(np.array([0.0, 0.0]), np.array([2.0, 0.0]), posts, CLEARANCE, 0.1)
    assert gap.length == pytest.approx(2.0)
    wall = posts + [Circle(1.0, 0.0, 0.3)]
    around = plan_way(np.array([0.0, 0.0]), np.array([2.0, 0.0]), wall, CLEARANCE, 0.1)
    assert around.found and around.length > 2.0
    assert_clear(around, wall, CLEARANCE)


@pytest.mark.parametrize("seed", range(20))
def test_random_fields_give_ways_clear_of_every_grown_disc_and_no_shorter_than_straight(
    seed: int,
) -> None:
    rng = np.random.default_rng(seed)
    circles = [Circle(*rng.uniform(-1.0, 1.0, 2), rng.uniform(0.05, 0.2)) for _ in range(6)]
    start, target = np.array([-1.8, rng.uniform(-1, 1)]), np.array([1.8, rng.uniform(-1, 1)])
    way = plan_way(start, target, circles, CLEARANCE, 0.1)
    if not way.found:
        assert "no way round the obstacles" in way.reason
        return
    assert way.length >= np.hypot(*(target - start)) - 1e-12
    assert_clear(way, circles, CLEARANCE)
    planner = WayPlanner(start, circles, CLEARANCE, 0.1)
    again = planner.to(target)
    assert again.length == pytest.approx(way.length, rel=1e-12)


def test_an_enclosed_target_has_no_way_and_says_so() -> None:
    ring = [
        Circle(2.0 + 0.9 * math.cos(a), 0.9 * math.sin(a), 0.08)
        for a in np.linspace(0.0, 2.0 * math.pi, 30, endpoint=False)
    ]
    way = plan_way(np.zeros(2), np.array([2.0, 0.0]), ring, CLEARANCE, 0.1)
    assert not way.found and math.isinf(way.length)
    assert "no way round the obstacles from (0.00, 0.00) to (2.00, 0.00)" in way.reason


def test_a_target_within_the_clearance_or_a_start_inside_an_obstacle_is_named() -> None:
    circle = Circle(1.0, 0.0, 0.1)
    near = plan_way(np.zeros(2), np.array([1.2, 0.0]), [circle], CLEARANCE)
    assert "lies within 0.215 m of obstacle 1" in near.reason
    inside = plan_way(np.array([1.05, 0.0]), np.array([3.0, 0.0]), [circle], CLEARANCE)
    assert "the base stands inside obstacle 1" in inside.reason


def test_a_start_in_the_slack_first_leaves_it_straight_away_from_the_obstacle() -> None:
    """A base that stands closer than clearance + slack (a goal's start, or a re-plan beside
    the obstacle) first moves straight out of the slack, then takes the way round with the
    slack kept."""
    circle = Circle(0.0, 0.0, 0.1)
    start = np.array([0.0, -0.36])
    way = plan_way(start, np.array([0.0, 1.0]), [circle], CLEARANCE, 0.1)
    assert way.found
    np.testing.assert_allclose(way.waypoints[0], [0.0, -0.415], atol=1e-3)
    assert_clear(way, [circle], CLEARANCE)
    rest = polyline(way)[1:]
    for a, b in zip(rest, rest[1:], strict=False):
        assert distance_to_segment(np.zeros(2), a, b) >= circle.radius + CLEARANCE + 0.1 - 1e-9
