"""The cascade of appendix B (wbc/laws/cascade_law.py) held to the robot's limits
(``CascadeParams.saturate``): the LP's bounds on u and the wheel speed limit, read from the
robot's description, never a NaN clamped."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.wbc.wbc_scenarios import integrate, pose_task, position_task, robot
from wbc.base_motion import unicycle
from wbc.geometry.scenarios import HOME, REACH_GOAL
from wbc.laws.cascade_law import CascadeLaw, CascadeParams, saturated
from wbc.robot import BASE_DOF

MODEL = robot()
TASKS = {"pose": pose_task(MODEL, REACH_GOAL), "position": position_task(MODEL, REACH_GOAL)}


def wheel_peak(u: np.ndarray, phi: float) -> float:
    forward, angular = unicycle(u[0], u[1], u[2], phi)
    return abs(forward) + abs(angular) * MODEL.base.wheel_base / 2.0


@pytest.mark.parametrize("name", TASKS)
def test_the_saturated_cascade_keeps_every_bound_the_lp_obeys_and_still_converges(
    name: str,
) -> None:
    """As appendix B runs it, the cascade drives the base at 0.55 m/s on the position task
    (past the LP's 0.2 and the wheels' 0.5) and turns it at 2.08 rad/s on the pose task (past
    1.5); saturated, no step leaves a bound, 5.11 still holds, and the task converges."""
    bounds = MODEL.velocity_max
    free = integrate(CascadeLaw(MODEL, CascadeParams(eta=1.0)), HOME, TASKS[name], 4000)
    assert any(np.any(np.abs(out.u) > bounds + 1e-9) for out in free.outputs)  # unchanged
    run = integrate(
        CascadeLaw(MODEL, CascadeParams(eta=1.0, saturate=True)), HOME, TASKS[name], 4000
    )
    assert run.converged, run.final_error
    for q, out in zip(run.configurations, run.outputs, strict=True):
        assert np.all(np.abs(out.u) <= bounds + 1e-12), out.u
        assert wheel_peak(out.u, q[2]) <= MODEL.base.wheel_speed_max + 1e-12
        assert out.u[0] * math.sin(q[2]) - out.u[1] * math.cos(q[2]) == pytest.approx(
            0.0, abs=1e-12
        )  # 5.11


def test_the_base_slows_along_its_path_and_each_joint_is_clipped_alone() -> None:
    """(v, omega) scaled by one factor (the curvature kept) until x', y', phi' and the wheels
    are inside their bounds; an arm joint over its bound clipped, the others as asked."""
    phi = 0.3
    u = np.array([0.6 * math.cos(phi), 0.6 * math.sin(phi), 2.0, 0.1, -2.0, 0.5, 3.0, -0.2])
    out = saturated(u, phi, MODEL)
    forward, angular = unicycle(*out[:BASE_DOF], phi)
    assert angular / forward == pytest.approx(2.0 / 0.6)
    assert np.max(np.abs(out[:BASE_DOF]) / MODEL.velocity_max[:BASE_DOF]) == pytest.approx(1.0)
    np.testing.assert_allclose(out[BASE_DOF:], np.clip(u[BASE_DOF:], -0.8, 0.8))
    inside = np.array([0.1 * math.cos(phi), 0.1 * math.sin(phi), 0.2, 0.1, 0.2, 0.3, 0.4, 0.5])
    np.testing.assert_allclose(saturated(inside, phi, MODEL), inside, atol=1e-15)


def test_a_base_going_backwards_keeps_its_direction() -> None:
    phi = 0.0
    out = saturated(np.array([-0.6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]), phi, MODEL)
    assert out[0] == pytest.approx(-MODEL.velocity_max[0]) and out[1] == 0.0


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_a_u_that_is_not_finite_is_never_clamped_to_a_bound(bad: float) -> None:
    """A NaN clamped would leave as a bound's speed: it is returned as it is, for the
    controller to refuse (its non-finite check)."""
    u = np.array([0.1, 0.0, 0.0, bad, 3.0, 0.0, 0.0, 0.0])
    out = saturated(u, 0.0, MODEL)
    assert not np.all(np.isfinite(out)) and out[4] == 3.0
