"""The active set the LP names (wbc/laws/active_set.py) against its plain definition, entry by
entry, over random u and bounds: near and far, infinite, degenerate (equal or within the
tolerance) and changing from step to step as a fixed base's and a moving joint's do."""

from __future__ import annotations

import numpy as np

from wbc.laws.active_set import ACTIVE_TOLERANCE, BoundEntries, active

CHOICES = ("far", "at_low", "at_high", "near", "equal", "narrow", "infinite", "one_infinite")


def reference(name: str, u: list[float], lows: list[float], highs: list[float]) -> list[str]:
    """``name[i]`` for every u_i within the tolerance of a bound, where the bounds are more than
    the tolerance apart."""
    return [
        f"{name}[{i}]"
        for i, (x, low, high) in enumerate(zip(u, lows, highs, strict=True))
        if (x - low <= ACTIVE_TOLERANCE or high - x <= ACTIVE_TOLERANCE)
        and high - low > ACTIVE_TOLERANCE
    ]


def entry(rng: np.random.Generator, kind: str) -> tuple[float, float, float]:
    """u_i and its two bounds, of one ``kind``."""
    low, high = -rng.uniform(0.0, 2.0), rng.uniform(0.0, 2.0)
    x = rng.uniform(low, high)
    step = ACTIVE_TOLERANCE * rng.choice([0.5, 1.0, 1.5, 2.0])
    if kind == "at_low":
        x = low
    elif kind == "at_high":
        x = high
    elif kind == "near":
        x = rng.choice([low + step, high - step])
    elif kind == "equal":
        x = low = high = rng.choice([0.0, -0.0, 0.3])
    elif kind == "narrow":
        high = low + rng.uniform(0.0, ACTIVE_TOLERANCE)
        x = rng.choice([low, high])
    elif kind == "infinite":
        low, high = -np.inf, np.inf
    elif kind == "one_infinite":
        low, high = (-np.inf, high) if rng.random() < 0.5 else (low, np.inf)
        x = high if np.isfinite(high) else low
    return float(x), float(low), float(high)


def test_the_velocity_entries_named_are_those_of_the_definition_at_every_step() -> None:
    rng = np.random.default_rng(35)
    for n in (1, 3, 9, 15):
        entries = BoundEntries("limits", n)
        # Each entry keeps its kind for a while, as a joint's bounds do, then changes it.
        kinds = rng.choice(CHOICES, n)
        for _ in range(150):
            changing = rng.random(n) < 0.1
            kinds = np.where(changing, rng.choice(CHOICES, n), kinds)
            u, lows, highs = map(list, zip(*(entry(rng, kind) for kind in kinds), strict=True))
            named = active(np.array(u), u, list(map(abs, u)), (), (), [(entries, lows, highs)])
            assert list(named) == reference("limits", u, lows, highs)


def test_a_fixed_base_is_never_named_and_its_arm_is() -> None:
    """Zero bounds on u_b (a fixed base) with u_b = 0: only the arm's entry at its bound."""
    entries = BoundEntries("joint_limits", 5)
    lows, highs = [-0.0, 0.0, 0.0, -0.8, -0.5], [0.0, 0.0, -0.0, 0.8, 0.5]
    for u in ([0.0, 0.0, 0.0, 0.1, 0.2], [0.0, 0.0, 0.0, 0.1, 0.5], [0.0, 0.0, 0.0, -0.8, 0.5]):
        named = active(np.array(u), u, list(map(abs, u)), (), (), [(entries, lows, highs)])
        assert list(named) == reference("joint_limits", u, lows, highs)
    assert named == ("joint_limits[3]", "joint_limits[4]")
