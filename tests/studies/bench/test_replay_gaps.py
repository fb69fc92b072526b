"""The replay bench's gap matching: each arrival paired with its recorded message by key and
order, and the error of each gap between consecutive recorded messages."""

from __future__ import annotations

import pytest

from studies.bench.recording import gap_errors_ms

MS = 1_000_000


def test_a_replay_on_time_has_no_gap_error_at_its_rate() -> None:
    recorded = [("camera/image", 0), ("robot/state", 10 * MS), ("camera/image", 33 * MS)]
    arrivals = {"camera/image": [5_000 * MS, 5_016 * MS + MS // 2], "robot/state": [5_005 * MS]}
    assert gap_errors_ms(recorded, arrivals, rate=2.0) == [0.0, 0.0]


def test_a_late_message_shows_in_the_gaps_before_and_after_it() -> None:
    recorded = [("a", 0), ("b", 10 * MS), ("a", 20 * MS)]
    arrivals = {"a": [0, 20 * MS], "b": [13 * MS]}
    assert gap_errors_ms(recorded, arrivals, rate=1.0) == pytest.approx([3.0, 3.0])


def test_arrivals_are_matched_per_key_in_order_whatever_the_order_across_keys() -> None:
    recorded = [("a", 0), ("b", 0), ("a", 10 * MS), ("b", 10 * MS)]
    arrivals = {"b": [1 * MS, 14 * MS], "a": [0, 10 * MS]}
    assert gap_errors_ms(recorded, arrivals, rate=1.0) == pytest.approx([1.0, 1.0, 4.0])


def test_a_message_that_never_arrived_leaves_out_its_two_gaps() -> None:
    recorded = [("a", 0), ("a", 10 * MS), ("b", 15 * MS), ("a", 20 * MS)]
    arrivals = {"a": [0, 12 * MS, 20 * MS]}  # b lost
    assert gap_errors_ms(recorded, arrivals, rate=1.0) == pytest.approx([2.0])
