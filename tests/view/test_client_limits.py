"""view.client_limits: what an answer repeats of a client's values, and the goal rate, on a
clock the test gives (no wall-clock time)."""

from __future__ import annotations

import pytest

from view.client_limits import ECHO_CHARS, TOLD_EVERY_S, Bucket, Rate, echo

RATE = Rate(per_s=2.0, burst=3)


@pytest.mark.parametrize(
    ("value", "shown"),
    [
        ("x" * 1_000_000, f"'{'x' * ECHO_CHARS}... (1000000 characters)'"),
        (10**400, "an integer of 401 digits"),
        (-3, "-3"),
        (1e300, "1e+300"),
        (b"\0" * 7, "7 bytes"),
        ([[1]] * 5, "a list of 5 entries"),
        ({"a": {"b": 1}}, "an object of 1 entries"),
        (True, "true"),
        (None, "null"),
    ],
)
def test_an_answer_repeats_a_client_value_in_a_few_words(value: object, shown: str) -> None:
    assert echo(value) == shown


def test_a_burst_passes_then_one_goal_per_period() -> None:
    bucket = Bucket(RATE)
    assert [bucket.take(10.0) for _ in range(4)] == [True, True, True, False]
    assert bucket.wait_s() == pytest.approx(0.5)
    assert not bucket.take(10.4)  # 0.8 of a goal come back
    assert bucket.take(10.5) and not bucket.take(10.5)
    assert bucket.take(20.0) and bucket.take(20.0) and bucket.take(20.0)  # never over burst
    assert not bucket.take(20.0)


def test_a_client_is_told_of_its_drops_at_once_then_at_most_every_period() -> None:
    bucket = Bucket(RATE)
    for _ in range(3):
        bucket.take(0.0)
    told = []
    for step in range(40):  # 40 goals over 1.95 s, 0.05 s apart
        now = step * 0.05
        if not bucket.take(now):
            told.append((now, bucket.tell(now)))
    said = [(now, count) for now, count in told if count]
    assert said[0] == (0.0, 1)
    assert all(b[0] - a[0] >= TOLD_EVERY_S for a, b in zip(said, said[1:], strict=False))
    assert sum(count for _, count in said) + bucket.dropped == len(told)
