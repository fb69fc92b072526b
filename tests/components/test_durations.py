"""A handler's durations reach its status as the median and p99 in whole microseconds, of the
last ``WINDOW`` notes, refreshed on each of the first ``EVERY`` notes and every ``EVERY`` after."""

from __future__ import annotations

from components.durations import EVERY, WINDOW, Durations


def noted(milliseconds: list[int]) -> dict[str, int]:
    counters: dict[str, int] = {}
    durations = Durations(counters, "step")
    for ms in milliseconds:
        durations.note(ms / 1e3)
    return counters


def test_one_note_is_its_median_and_p99_in_microseconds() -> None:
    assert noted([2]) == {"step_us_median": 2000, "step_us_p99": 2000}


def test_median_and_p99_of_the_first_notes() -> None:
    counters = noted(list(range(49, 0, -1)))  # 49 notes of 49 .. 1 ms, out of order
    assert counters == {"step_us_median": 25_000, "step_us_p99": 49_000}


def test_the_p99_leaves_out_the_worst_hundredth() -> None:
    counters = noted(list(range(1, 201)))  # 200 notes, the 200th refreshes
    assert counters == {"step_us_median": 101_000, "step_us_p99": 199_000}


def test_after_the_first_notes_it_refreshes_every_few() -> None:
    assert EVERY == 50
    first = list(range(1, 50)) + [100]  # the 50th refreshes: 1 .. 49 and 100 ms
    assert noted(first) == {"step_us_median": 26_000, "step_us_p99": 100_000}
    assert noted([*first, 1000, 1000]) == noted(first)  # the 51st and 52nd do not


def test_only_the_last_window_of_notes_counts() -> None:
    counters = noted([1000] * WINDOW + [1] * WINDOW)
    assert counters == {"step_us_median": 1000, "step_us_p99": 1000}
