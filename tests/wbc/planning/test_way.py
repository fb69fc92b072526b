"""The way the planner hands the drive (wbc/planning/way.py): an arc's circumscribed corners,
the way's turning and the bearings of its first and last legs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wbc.planning.way import Arc, Way


def test_an_arcs_corners_lie_outside_the_disc_at_most_max_turn_apart() -> None:
    arc = Arc(centre=(1.0, 0.0), radius=0.5, start=0.0, sweep=math.pi / 2)
    corners = arc.corners(math.pi / 4)
    assert len(corners) == 2
    lifted = 0.5 / math.cos(math.pi / 8)
    for corner, angle in zip(corners, (math.pi / 8, 3 * math.pi / 8), strict=True):
        np.testing.assert_allclose(
            corner, [1.0 + lifted * math.cos(angle), lifted * math.sin(angle)]
        )
    assert len(Arc((0.0, 0.0), 1.0, 0.0, -0.1).corners(math.pi / 4)) == 1


def test_a_way_turns_on_its_arcs_alone_and_knows_its_first_and_last_bearings() -> None:
    start, target = np.array([0.0, 0.0]), np.array([2.0, 0.0])
    arc = Arc(centre=(1.0, 0.0), radius=0.5, start=math.pi, sweep=-math.pi)
    waypoints = (*arc.corners(math.pi / 4), target)
    way = Way(start, target, (arc,), 3.0, "", waypoints)
    assert way.found and way.turning == pytest.approx(math.pi)
    assert way.first_bearing() == pytest.approx(math.atan2(*(waypoints[0] - start)[::-1]))
    assert way.last_bearing() == pytest.approx(math.atan2(*(target - waypoints[-2])[::-1]))
    none = Way(start, target, (), math.inf, "walled off", ())
    assert not none.found and none.turning == 0.0
