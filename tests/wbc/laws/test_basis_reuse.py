"""Reusing the last optimal basis (wbc/laws/basis_reuse.py) gives HiGHS's optimum, on real runs."""

from __future__ import annotations

import numpy as np
import pytest

from tests.wbc.wbc_scenarios import pose_task, position_task, robot
from wbc.geometry.scenarios import DT, STARTS_AND_GOALS
from wbc.laws.lp_law import LPLaw

MODEL = robot()


@pytest.mark.parametrize("make_task", [pose_task, position_task])
@pytest.mark.parametrize("start, goal", STARTS_AND_GOALS[:2])
def test_a_kept_basis_gives_the_optimum_highs_gives_from_scratch(start, goal, make_task):
    """Two laws step through the same states: one reuses its basis when it is still optimal,
    the other starts HiGHS cold every step. Their objectives agree at every step, and the
    first calls HiGHS on few of them."""
    task = make_task(MODEL, goal)
    warm, cold = LPLaw(MODEL), LPLaw(MODEL)
    highs_runs = 0
    run_highs = warm._lp._run

    def counted(layout):
        nonlocal highs_runs
        highs_runs += 1
        return run_highs(layout)

    warm._lp._run = counted
    q = np.array(start, dtype=float)
    steps = 400
    for _ in range(steps):
        out = warm.step(q, task, DT)
        cold._lp.reset()
        reference = cold.step(q, task, DT)
        assert out.status == reference.status == "optimal"
        assert out.objective == pytest.approx(reference.objective, abs=1e-9)
        q = q + out.u * DT
    assert highs_runs < steps / 2
