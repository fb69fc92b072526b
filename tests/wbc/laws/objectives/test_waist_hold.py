"""The waist hold (wbc/laws/objectives/waist_hold.py): the task's yaw goes to the base."""

from __future__ import annotations

import numpy as np
import pytest

from tests.wbc.laws.objectives.objective_steps import MODEL, WAIST, YAW
from wbc.geometry.scenarios import DT, HOME
from wbc.laws.lp_law import LPLaw
from wbc.laws.objectives.waist_hold import WaistHold
from wbc.task import PoseTask


def test_the_waist_hold_gives_the_tasks_yaw_to_the_base_at_no_cost_in_entries():
    """phi' and q1' are never both nonzero (the split would be an eighth entry), and the waist
    stays where it is."""
    task = PoseTask(MODEL.fkm(np.concatenate(([0.3, 0.1, 0.2, 0.3], HOME[4:]))))
    start = HOME.copy()
    start[WAIST] = 0.2
    law = LPLaw(MODEL)
    for _ in range(50):
        out = law.step(start, task, DT)
        assert not (abs(out.u[YAW]) > 1e-9 and abs(out.u[WAIST]) > 1e-9), out.u
        assert out.nonzero <= 7
        start = start + DT * out.u
    assert start[WAIST] == pytest.approx(0.2)


@pytest.mark.parametrize(
    "make",
    [
        lambda: WaistHold(-1e-3),
    ],
)
def test_invalid_waist_hold_gains_are_refused(make):
    with pytest.raises(ValueError):
        make()
