"""What every law returns (wbc/laws/law_output.py): u frozen, its nonzero and practical entries."""

from __future__ import annotations

import time

import numpy as np
import pytest

from wbc.laws.law_output import PRACTICAL_THRESHOLD, ZERO_THRESHOLD, entry_mask, summarise


def test_entry_mask_sets_a_bit_per_nonzero_entry_and_practical_ones_apart() -> None:
    u = np.array([0.0, 1e-10, 2e-9, -0.5, PRACTICAL_THRESHOLD, 0.009])
    assert entry_mask(u) == 0b111100
    assert entry_mask(u, practical=True) == 0b011000


def test_summarise_counts_the_entries_and_freezes_u() -> None:
    u = [0.0, ZERO_THRESHOLD / 2, 0.005, -0.2, 0.0, 0.0, 0.0, 1.0]
    out = summarise(u, "optimal", 1.5, ("joint_limits",), np.array([3.0, 4.0]), time.perf_counter())
    assert out.ok and (out.nonzero, out.practical_nonzero) == (3, 2)
    assert out.error_norm == pytest.approx(5.0) and out.solve_time_s >= 0.0
    with pytest.raises(ValueError):
        out.u[0] = 1.0
    assert not summarise(u, "infeasible", None, (), np.zeros(8), time.perf_counter()).ok
