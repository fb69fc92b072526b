"""The classic law u = -J^+ eta e (wbc.laws.pinv_law), on random states: among the velocities
with the same task velocity J u, its u has the least 2-norm (with no constraint, or under 5.11)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings

from tests.wbc.laws.drawn_states import MODEL, states, unit
from wbc.geometry.scenarios import DT
from wbc.laws.pinv_law import PinvParams, PseudoinverseLaw, nonholonomic_basis


@settings(max_examples=40, deadline=None)
@given(unit, unit)
def test_the_pseudoinverse_takes_the_least_2_norm_for_its_task_velocity(a, b) -> None:
    q, task = states(a, b)
    pose, jacobian = MODEL.kinematics(q)
    _, task_jacobian = task.error(pose, jacobian, q)
    for nonholonomic in (False, True):
        u = PseudoinverseLaw(MODEL, PinvParams(nonholonomic=nonholonomic)).step(q, task, DT).u
        basis = nonholonomic_basis(q[2], MODEL.dof) if nonholonomic else np.eye(MODEL.dof)
        # Any other velocity of the same J u inside the allowed space is u + N z, J N z = 0:
        # u is orthogonal to every such N z.
        _, singular, vt = np.linalg.svd(task_jacobian @ basis)
        null = basis @ vt[np.sum(singular > 1e-9 * singular[0]) :].T
        assert np.allclose(null.T @ u, 0.0, atol=1e-9)
