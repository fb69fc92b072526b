"""The base's pose from odometry and late camera fixes (wbc/base_estimate.py)."""

from __future__ import annotations

import math

import pytest

from wbc.base_estimate import BaseEstimate, blend

S = 1_000_000_000


def test_blend_takes_the_heading_the_shorter_way_round() -> None:
    x, y, phi = blend((0.0, 0.0, 3.0), (1.0, 2.0, -3.0), 0.5)
    assert (x, y) == (0.5, 1.0)
    assert phi == pytest.approx(3.0 + 0.5 * (2 * math.pi - 6.0))  # across pi, not through 0


def test_no_pose_before_a_fix_and_the_first_fix_places_the_base() -> None:
    estimate = BaseEstimate()
    estimate.move(0, (0.0, 0.0, 0.0))
    assert estimate.pose is None
    assert estimate.fix(0, (1.0, 2.0, 0.5), gain=0.1)
    assert estimate.pose == pytest.approx((1.0, 2.0, 0.5))


def test_a_late_fix_enters_at_its_own_time_and_the_odometry_since_is_laid_on_it() -> None:
    estimate = BaseEstimate()
    estimate.move(0, (0.0, 0.0, 0.0))
    estimate.fix(0, (0.0, 0.0, 0.0), gain=1.0)
    estimate.move(S, (1.0, 0.0, 0.0))
    estimate.move(2 * S, (2.0, 0.0, 0.0))
    # a fix taken at 0.5 s, half a metre to the left of where the odometry then was
    assert estimate.fix(S // 2, (0.5, 0.5, 0.0), gain=1.0)
    assert estimate.pose == pytest.approx((2.0, 0.5, 0.0))


def test_a_fix_no_odometry_covers_is_refused() -> None:
    estimate = BaseEstimate(horizon_s=1.0)
    assert not estimate.fix(0, (0.0, 0.0, 0.0), gain=1.0)  # no odometry yet
    for k in range(4):
        estimate.move(k * S, (float(k), 0.0, 0.0))
    assert not estimate.fix(S, (0.0, 0.0, 0.0), gain=1.0)  # older than the horizon
    assert estimate.odometry_at(int(2.5 * S)) == pytest.approx((2.5, 0.0, 0.0))
    assert estimate.odometry_at(10 * S) == (3.0, 0.0, 0.0)  # after the last: the last
