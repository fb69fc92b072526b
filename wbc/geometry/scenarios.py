"""The configurations of the chapter 6 experiments on this robot, declared once.

The demo, the bench, the tests, the latency benchmark and the profiles (checked by a test)
take their starts and goals from here. Configurations are q = [x, y, phi, q1..q5].
"""

from __future__ import annotations

import numpy as np

from wbc.geometry.obstacles import Circle
from wbc.geometry.obstacles3d import Plane

DT = 0.02
"""The control period of the dissertation's experiments: 50 Hz (section 6.3)."""

HOME = np.array([0.0, 0.0, 0.0, 0.0, -0.2, 0.2, 0.0, 0.5])
"""The start of the experiments: base at the origin facing x, the arm raised."""

REACH_GOAL = np.array([0.58, 0.05, -0.16, 0.3, 0.15, -0.66, -0.03, -0.36])
"""The pose and position experiments' goal (6.2.1, 6.2.2): an end effector some 0.5 m ahead."""

CONVERGENCE_GOAL = np.array([0.45, -0.29, -0.12, 0.23, -0.26, 0.14, -0.28, -0.3])
"""The goal of the convergence test of section 6.3."""

JOINT_LIMIT_GOAL = np.array([0.3, 0.0, 0.0, 0.0, -0.2, 0.9, 0.0, 0.5])
"""Figure 6.10: the nearest arm pose puts the elbow q3 beyond its limit."""

OBSTACLE_GOAL = np.concatenate(([1.3, 0.3, 0.2], HOME[3:]))
OBSTACLE = Circle(0.56, 0.16, 0.1)
"""Section 6.2.3: an obstacle on the path the default LP law's base takes to OBSTACLE_GOAL."""

TABLE = Plane(
    (0.0, 0.0, 1.0), 0.40, ((0.55, -0.4), (1.15, -0.4), (1.15, 0.4), (0.55, 0.4)), "table"
)
"""Reaching over a table edge (future work 3 of 7.2): a 0.6 x 0.8 m table top 0.40 m high, its
near edge 0.55 m ahead of HOME's base; the solid is the top and what lies under it."""
TABLE_START = np.array([0.0, 0.0, 0.0, 0.0, 0.3, -0.3, 0.0, 0.0])
"""The arm low and straight ahead, 0.31 m high: under the table's height, short of its edge."""
TABLE_GOAL = np.array([0.33, 0.0, 0.0, 0.0, -0.6, 0.2, -1.0, 0.4])
"""The gripper 0.18 m beyond the edge and 0.1 m above the top, the base 0.055 m short of the
table (body radius included). From TABLE_START the unconstrained LP's hand cuts through the
edge on the way (3.9 cm deep in the kinematic loop)."""

NEAR_START = np.array([0.07, 0.0, 0.13, 0.03, 0.09, 0.02, 0.03, 0.49])
"""A start near HOME, the state of deploy/controllers.yaml's scripted publisher."""

STARTS_AND_GOALS = (
    (
        np.array([-0.15, 0.0, 0.04, -0.28, -0.41, 0.3, -0.26, 0.28]),
        np.array([0.87, 0.07, -0.08, 0.01, -0.07, -0.5, -0.36, 0.46]),
    ),
    (NEAR_START, REACH_GOAL),
    (np.array([0.1, -0.12, -0.18, 0.06, 0.04, -0.08, 0.18, 0.31]), CONVERGENCE_GOAL),
)
"""Closed-loop test cases: goals 0.4 to 0.9 m ahead, as in the pick and place of 6.2."""

ARM_BOX = (np.array([-0.5, -0.8, -0.8, -0.5, -0.8]), np.array([0.5, 0.3, 0.3, 0.5, 0.8]))
"""A moderate box of arm angles (rad) inside the 0.9-scaled joint limits: random goals'."""

for _configuration in (
    HOME,
    REACH_GOAL,
    CONVERGENCE_GOAL,
    JOINT_LIMIT_GOAL,
    OBSTACLE_GOAL,
    TABLE_START,
    TABLE_GOAL,
    NEAR_START,
    *ARM_BOX,
):
    _configuration.flags.writeable = False
