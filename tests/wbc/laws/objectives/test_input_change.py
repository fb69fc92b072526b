"""The input change term (wbc/laws/objectives/input_change.py): its cost against a direct
computation, and the LP law with it (as deploy/sim_smooth.yaml sets it) against the same law
without it on the same runs."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from studies.gain_sets import LP_PARAMS, input_change_gains
from tests.wbc.wbc_scenarios import context, integrate, robot
from wbc import dq
from wbc.geometry.scenarios import DT, HOME, JOINT_LIMIT_GOAL, REACH_GOAL
from wbc.laws.kinematic_run import control_effort
from wbc.laws.lp_law import LPLaw
from wbc.laws.objectives.input_change import InputChange
from wbc.task import PoseTask, PositionTask

MODEL = robot()
SMOOTH = input_change_gains()
RAMP_S = SMOOTH["input_change_ramp"]
POSE, POSITION = LP_PARAMS["pose"], LP_PARAMS["position"]


def term_cost(term: InputChange, previous: np.ndarray, u: np.ndarray) -> float:
    """What the LP adds for u: weight * ||A u + b||_1 of the term's residual cost."""
    cost = term.cost(context(MODEL, HOME, previous_u=previous))
    return cost.weight * float(np.abs(cost.matrix @ u + cost.offset).sum())


def test_the_change_form_costs_w_times_the_one_norm_of_the_change() -> None:
    rng = np.random.default_rng(0)
    term = InputChange(0.3, "change")
    for _ in range(20):
        previous, u = rng.uniform(-1.0, 1.0, (2, MODEL.dof))
        assert term_cost(term, previous, u) == pytest.approx(
            0.3 * np.abs(u - previous).sum(), abs=1e-12
        )


def test_speeding_up_costs_w_times_the_speed_gained_beyond_the_ramp_and_stopping_is_free() -> None:
    """w sum_i dist(u_i, [min(p_i - s_i, 0), max(p_i + s_i, 0)]) with s = v dt / T, plus a
    constant; u = 0 and any u between 0 and p cost only the constant."""
    rng = np.random.default_rng(1)
    term = InputChange(0.3, "speeding_up", RAMP_S)
    step = MODEL.velocity_max * DT / RAMP_S
    for _ in range(20):
        previous = rng.uniform(-1.0, 1.0, MODEL.dof) * rng.integers(0, 2, MODEL.dof)
        u = rng.uniform(-1.0, 1.0, MODEL.dof)
        low, high = np.minimum(previous - step, 0.0), np.maximum(previous + step, 0.0)
        beyond = np.maximum(np.maximum(low - u, u - high), 0.0).sum()
        constant = term_cost(term, previous, np.zeros(MODEL.dof))
        assert term_cost(term, previous, u) == pytest.approx(0.3 * beyond + constant, abs=1e-12)
        slower = previous * rng.uniform(0.0, 1.0, MODEL.dof)
        assert term_cost(term, previous, slower) == pytest.approx(constant, abs=1e-12)


def test_without_a_previous_u_the_term_is_idle() -> None:
    assert InputChange(0.3).cost(context(MODEL, HOME)).weight == 0.0


def test_invalid_term_parameters_are_refused() -> None:
    with pytest.raises(ValueError, match="input change"):
        InputChange(-0.1)
    with pytest.raises(ValueError, match="input change"):
        InputChange(0.1, "speeding_up", 0.0)
    with pytest.raises(ValueError, match="input change"):
        InputChange(0.1, "smooth")  # type: ignore[arg-type]


def test_a_heavy_term_holds_the_ramp_from_rest_at_every_step() -> None:
    """At w 3 the band is a bound: from rest (u = 0 before the first step, which a new law
    assumes) no entry speeds up by more than s = v dt / T a step, and the goal is reached."""
    params = dataclasses.replace(POSE, input_change=3.0, input_change_ramp=RAMP_S)
    run = integrate(LPLaw(MODEL, params), HOME, PoseTask(MODEL.fkm(REACH_GOAL)), steps=4000)
    assert run.converged
    u = np.vstack((np.zeros(MODEL.dof), run.velocities()))
    step = MODEL.velocity_max * DT / RAMP_S
    low, high = np.minimum(u[:-1] - step, 0.0), np.maximum(u[:-1] + step, 0.0)
    assert np.all(u[1:] >= low - 1e-9) and np.all(u[1:] <= high + 1e-9)


def test_the_previous_u_outlives_a_reset_the_robot_does_not_stop_for_a_new_task() -> None:
    """A law reset for a new task keeps the u it gave last: its next u stays in the band about
    that u (w 3 makes the band a bound), where the law without the term jumps out of it."""
    law = LPLaw(MODEL, dataclasses.replace(POSE, input_change=3.0, input_change_ramp=RAMP_S))
    q = HOME.copy()
    for _ in range(30):
        before = law.step(q, PoseTask(MODEL.fkm(REACH_GOAL)), DT).u
        q = q + DT * before
    other = PoseTask(MODEL.fkm(JOINT_LIMIT_GOAL))
    law.reset()
    after = law.step(q, other, DT).u
    step = MODEL.velocity_max * DT / RAMP_S
    low, high = np.minimum(before - step, 0.0), np.maximum(before + step, 0.0)
    assert np.all(after >= low - 1e-9) and np.all(after <= high + 1e-9)
    plain = LPLaw(MODEL, POSE).step(q, other, DT).u
    assert np.any((plain < low - 1e-6) | (plain > high + 1e-6))


@pytest.mark.parametrize(
    "params, task",
    [
        (POSE, PoseTask(MODEL.fkm(REACH_GOAL))),
        (POSITION, PositionTask(dq.translation(MODEL.fkm(REACH_GOAL))[1:])),
    ],
    ids=["6.2.1 pose", "6.2.2 position"],
)
def test_the_term_lowers_metric_4_on_the_same_run_and_keeps_it_parsimonious(params, task):
    """The runs of 6.2.1 and 6.2.2 with the term and without (the default): both converge,
    metric 4 of table 6.1, counted from rest, is lower with it, and the median nonzero entries
    while moving (||e|| > 0.05) do not grow."""
    assert params.input_change == 0.0
    smooth = integrate(LPLaw(MODEL, dataclasses.replace(params, **SMOOTH)), HOME, task, 4000)
    plain = integrate(LPLaw(MODEL, params), HOME, task, 4000)
    assert smooth.converged and plain.converged
    efforts = [control_effort(run, from_rest=True) for run in (smooth, plain)]
    assert efforts[0].acceleration_l2 < efforts[1].acceleration_l2

    def moving(run) -> float:
        return float(np.median([o.nonzero for o in run.outputs if o.error_norm > 0.05]))

    assert moving(smooth) <= moving(plain)
