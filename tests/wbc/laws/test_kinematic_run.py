"""Closed-loop kinematic runs and table 6.1's control effort (wbc/laws/kinematic_run.py)."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from profiles.deploy_files import ROBOT_FILE
from wbc import dq
from wbc.geometry.scenarios import DT, HOME
from wbc.laws.kinematic_run import Run, control_effort, effort_of, integrate
from wbc.laws.law_output import summarise
from wbc.laws.pinv_law import PseudoinverseLaw
from wbc.robot import MobileManipulator
from wbc.task import PositionTask

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)


def test_a_run_steps_q_by_u_dt_and_stops_once_the_error_is_within_its_tolerance() -> None:
    task = PositionTask(dq.translation(ROBOT.fkm(HOME))[1:] + [0.03, 0.0, 0.0])
    run = integrate(PseudoinverseLaw(ROBOT), HOME, task, DT, 500, tolerance=1e-3)
    assert run.converged and run.final_error < 1e-3
    assert len(run.configurations) == len(run.outputs) < 500
    np.testing.assert_array_equal(run.configurations[0], HOME)
    np.testing.assert_allclose(run.configurations[1], HOME + DT * run.outputs[0].u)
    short = integrate(PseudoinverseLaw(ROBOT), HOME, task, DT, 2, tolerance=1e-3)
    assert not short.converged and len(short.outputs) == 2


def test_effort_is_table_6_1s_integrals_of_the_velocities_and_their_differences() -> None:
    velocity = np.array([[1.0, -1.0], [3.0, -1.0]])
    effort = effort_of(velocity, 0.5)
    assert effort.velocity_l1 == pytest.approx(6.0 * 0.5)
    assert effort.velocity_l2 == pytest.approx(math.sqrt(12.0 * 0.5))
    assert effort.acceleration_l1 == pytest.approx(4.0 * 0.5)  # (3 - 1) / 0.5, once
    assert effort.acceleration_l2 == pytest.approx(math.sqrt(16.0 * 0.5))


def test_from_rest_counts_the_jump_to_the_first_command() -> None:
    out = summarise([1.0, 0.0], "optimal", 0.0, (), np.zeros(2), time.perf_counter())
    run = Run(dt=0.5, outputs=[out])
    assert control_effort(run).acceleration_l1 == 0.0
    assert control_effort(run, from_rest=True).acceleration_l1 == pytest.approx(1.0)
