"""The waist centring (wbc/laws/objectives/waist_centring.py): the self-motion spent on q1 -> 0."""

from __future__ import annotations

import numpy as np
import pytest

from tests.wbc.laws.objectives.objective_steps import MODEL, WAIST, YAW, context
from wbc.geometry.scenarios import DT, HOME
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.objectives.waist_centring import WaistCentring
from wbc.task import PoseTask


def test_waist_centring_asks_for_q1_rate_minus_k_q1_and_fades_near_the_goal():
    q = HOME.copy()
    q[WAIST] = 0.4
    term = WaistCentring(weight=0.02, gain=1.5, fade_error=0.05)
    far = term.cost(context(q, None, np.full(8, 0.1)))
    u = np.zeros(MODEL.dof)
    u[WAIST] = -1.5 * 0.4
    assert far.weight == pytest.approx(0.02)
    assert abs((far.matrix @ u + far.offset)[0]) < 1e-12
    near = term.cost(context(q, None, np.full(8, 0.1 / 32)))  # ||e||_1 = 0.025
    assert near.weight == pytest.approx(0.01)


def test_the_law_spends_the_self_motion_on_centring_the_waist():
    """With the waist turned, the LP turns the base and the waist against each other
    (phi' = -q1' moves no part of the end effector, 4.9): q1 heads back to 0 at no cost to
    the task residual ||J u + eta e||_1. (The term is off by default.)"""
    goal = HOME.copy()
    start = goal.copy()
    start[YAW], start[WAIST] = -0.3, 0.3  # the same end-effector pose as the goal's
    np.testing.assert_allclose(MODEL.fkm(start), MODEL.fkm(goal), atol=1e-12)
    task = PoseTask(MODEL.fkm(np.concatenate(([0.02], goal[1:]))))  # 2 cm ahead
    pose, jacobian = MODEL.kinematics(start)
    error, _ = task.error(pose, jacobian)

    def residual(params: LPParams) -> tuple[np.ndarray, float]:
        u = LPLaw(MODEL, params).step(start, task, DT).u
        return u, float(np.abs(jacobian @ u + params.eta * error).sum())

    centring = {"base_target": 0.0, "waist_hold": 0.0}
    centred, centred_residual = residual(LPParams(waist_centring=0.02, **centring))
    _, plain_residual = residual(LPParams(waist_centring=0.0, **centring))
    assert centred[WAIST] < 0.0 < centred[YAW]
    assert centred_residual == pytest.approx(plain_residual, abs=1e-9)


@pytest.mark.parametrize(
    "make",
    [
        lambda: WaistCentring(-1.0, 1.0),
        lambda: WaistCentring(0.02, 0.0),
    ],
)
def test_invalid_waist_centring_gains_are_refused(make):
    with pytest.raises(ValueError):
        make()
