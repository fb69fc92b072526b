"""What chapter 6 of the dissertation reports, quoted once: the figures `parsimony reproduce`
sets its own beside."""

from __future__ import annotations

METRICS = ("velocity_l1", "velocity_l2", "acceleration_l1", "acceleration_l2")
"""Table 6.1's metrics 1..4, as ``wbc.laws.kinematic_run.ControlEffort`` names them."""

TABLE_6_1 = {
    "pose": {"PINV": (1.9796, 0.2960, 0.0026, 0.00013), "LP": (1.4944, 0.3267, 0.0012, 0.00004)},
    "position": {
        "PINV": (0.3907, 0.0583, 0.0047, 0.00084),
        "LP": (0.3431, 0.0654, 0.0021, 0.00085),
    },
}
"""Table 6.1: metrics 1..4 of each law in the pose and the position experiment."""

EXPECTED = ("< 1", "> 1", "< 1", "> 1")
"""The ratio LP / PINV of each metric as section 6.2.1's text has it: the 1-norm metrics (1, 3)
favour the LP, the 2-norm ones (2, 4) the classic law."""

CONTRADICTED = {
    ("pose", 3): "> 1 by the text; the dissertation's own table has < 1 (0.00004 against 0.00013)"
}
"""Where the dissertation's table contradicts its text: (task, metric index) and what the row
says. Each row compares with the text."""

ENTRIES = {
    "pose": {"LP": "7 while moving, 6 after the 150th iteration", "PINV": "8"},
    "position": {"LP": "5 most of the time", "PINV": "8"},
    "obstacle": {"LP": "8 most of the time: 6 for the task, 1 for 5.12, 1 for 5.28"},
}
"""Figures 6.7, 6.12 and 6.17: the nonzero entries of u each law generated (6.8 and 6.13 show
fewer used in practice)."""

ABRUPT = {"pose": "LP more abrupt (figs. 6.6, 6.9)", "position": "LP more abrupt (fig. 6.11)"}
"""What figures 6.6, 6.9 and 6.11 show of the inputs."""

SECTION_6_3 = {
    "test 1": {
        "trials": 10000,
        "iterations": 46,
        "classic_ms": (158.96, 5.23),
        "lp_ms": (173.42, 2.79),
    },
    "test 2": {
        "trials": 10000,
        "iterations": 77,
        "classic_ms": (251.03, 7.58),
        "lp_ms": (290.14, 4.30),
    },
}
"""Section 6.3: trials, iterations to ||e|| < 1e-3 (the same for both laws) and the
convergence time of a trial, mean and standard deviation (ms), classic law and LP."""

PERIOD_MS = 20.0
"""Section 6.3: each iteration under the 20 ms period of the 50 Hz control node."""

NOTES = {
    "pose/control_inputs.png": "fig. 6.6: the LP's inputs more abrupt than PINV's",
    "pose/nonzero_entries.png": "figs. 6.7, 6.8: LP 7 entries while moving and 6 after the "
    "150th iteration, fewer in practice (Upsilon 0.01); PINV all 8",
    "pose/error.png": "fig. 6.9: every coefficient of e converges, the LP's less smoothly",
    "pose/joints.png": "fig. 6.10: the LP inside every joint limit",
    "pose/saturated/control_inputs.png": "not in the dissertation: the cascade held to the "
    "robot's bounds, beside the LP",
    "pose/5.29/nonzero_entries.png": "not in the dissertation: 5.29 with no term beside the "
    "task, beside the default LP",
    "pose/two_norm.png": "not in the dissertation: ||u||_2 (table 6.1's metric 2) and the "
    "residual ||J u + eta e|| / ||eta e|| of each law at each step",
    "joint_limit/joints.png": "fig. 6.10: PINV past a joint's limit (q8 there), the LP inside",
    "position/control_inputs.png": "fig. 6.11: the LP's inputs more abrupt",
    "position/nonzero_entries.png": "figs. 6.12, 6.13: LP five entries most of the time; PINV 8",
    "position/end_effector_path.png": "fig. 6.14: both end effectors settle on the goal",
    "position/saturated/control_inputs.png": "not in the dissertation: the cascade held to the "
    "robot's bounds, beside the LP",
    "obstacle/nonzero_entries.png": "fig. 6.17: the LP uses all 8 entries most of the time",
    "obstacle/base_path.png": "fig. 6.16: the base goes round the obstacle",
    "obstacle/5.29/base_path.png": "fig. 6.16 with 5.29 as written (5.28 on the axle centre, "
    "5.10, no term): where its base stops",
}
"""What each of the dissertation's figures shows, beside the file of ours that draws it."""
