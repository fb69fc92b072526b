"""analysis.report_figures on sessions made of real kinematic runs of the LP."""

from __future__ import annotations

import numpy as np

from analysis import report as report_module
from analysis.report_figures import FIGURES as DRAWN
from messages.topics import ROBOT_STATE
from tests.analysis.conftest import ROBOT
from wbc import dq


def test_the_base_path_starts_at_the_first_valid_state(runs):
    """Before its first camera fix the estimator says (0, 0), invalid: the path is drawn from
    the first valid state, not with a line from there."""
    states = runs["LP"][1][ROBOT_STATE.name]
    moved = [
        s.model_copy(
            update={"base_pose": (s.base_pose[0] + 1.0, s.base_pose[1] + 2.0, s.base_pose[2])}
        )
        for s in states
    ]
    before_fix = [
        s.model_copy(update={"base_pose": (0.0, 0.0, 0.0), "valid": False}) for s in moved[:10]
    ]
    session = {**runs["LP"][1], ROBOT_STATE.name: before_fix + moved[10:]}
    recording = report_module._recording("LP", session, None, ROBOT)
    for name, where in (
        ("base_path.png", moved[10].base_pose[:2]),
        ("end_effector_path.png", dq.translation(np.array(moved[10].end_effector))[1:3]),
    ):
        figure = DRAWN[name]([recording], ROBOT)
        estimate = next(line for line in figure.axes[0].lines if line.get_label() == "estimate")
        np.testing.assert_array_equal(estimate.get_xydata()[0], where, err_msg=name)
        assert len(estimate.get_xydata()) == len(states) - 10, name
