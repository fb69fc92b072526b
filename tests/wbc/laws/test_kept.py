"""Kept arrays (wbc/laws/kept.py): the LP copies one into its program once, and a step that
finds it again in its place, or finds a writable array there again, solves what it is given."""

from __future__ import annotations

import numpy as np
import pytest

from wbc.laws.constraints.base import LinearRows, VelocityBounds, no_rows
from wbc.laws.kept import KEPT, kept, zeros
from wbc.laws.linear_program import LPSolution, WarmStartedLP
from wbc.laws.objectives.base import ResidualCost, VelocityCost, no_cost, unit_row

N = 6


def test_a_kept_array_is_read_only_one_per_shape_and_known_by_its_id() -> None:
    zero = zeros(1, N)
    assert zero is zeros(1, N) and id(zero) in KEPT
    with pytest.raises(ValueError, match="read-only"):
        zero[0, 0] = 1.0
    row = unit_row(N, 2)
    assert id(row) in KEPT and not row.flags.writeable
    assert id(kept(np.ones(2))) in KEPT


def problem(step: int, fresh: bool) -> tuple[list, list]:
    """Step ``step`` of a loop whose task and rows change, beside terms that return kept
    arrays (a switched-off term, a unit row, zero bounds); ``fresh``: every one a new copy."""
    rng = np.random.default_rng(step)
    copy = np.array if fresh else (lambda array: array)
    heading = np.zeros((1, N))
    heading[0, :2] = np.sin(0.1 * step), -np.cos(0.1 * step)
    costs = [
        ResidualCost("task", rng.normal(size=(4, N)), rng.normal(size=4)),
        VelocityCost("velocity", np.full(N, 1e-3)),
        ResidualCost("off", copy(no_cost("off", N).matrix), copy(zeros(1)), 0.0),
        ResidualCost("turn", copy(unit_row(N, 2)), np.array([0.1 * step]), 0.5),
    ]
    rows = [
        LinearRows("heading", heading, copy(zeros(1)), copy(zeros(1))),
        VelocityBounds("speed", np.full(N, -0.5 - 0.01 * step), np.full(N, 0.5)),
        no_rows("none", N),
    ]
    return costs, rows


def outputs(solutions: list[LPSolution]) -> list[tuple]:
    return [(s.u.tobytes(), s.status, s.objective, s.active) for s in solutions]


def test_the_lp_solves_the_same_with_kept_arrays_as_with_fresh_copies() -> None:
    kept_lp, fresh_lp = WarmStartedLP(), WarmStartedLP()
    with_kept = [kept_lp.solve(*problem(step, fresh=False)) for step in range(12)]
    with_copies = [fresh_lp.solve(*problem(step, fresh=True)) for step in range(12)]
    assert outputs(with_kept) == outputs(with_copies)
    assert all(solution.status == "optimal" for solution in with_kept)


def test_a_writable_array_returned_again_with_new_numbers_is_read_anew() -> None:
    """A term may fill one buffer of its own at every step: the same object, new numbers."""
    reused_lp, fresh_lp = WarmStartedLP(), WarmStartedLP()
    matrix, offset = np.zeros((4, N)), np.zeros(4)
    reused, fresh = [], []
    for step in range(8):
        costs, rows = problem(step, fresh=False)
        matrix[...], offset[...] = costs[0].matrix, costs[0].offset
        reused.append(
            reused_lp.solve([costs[0]._replace(matrix=matrix, offset=offset)] + costs[1:], rows)
        )
        fresh.append(fresh_lp.solve(*problem(step, fresh=False)))
    assert outputs(reused) == outputs(fresh)
