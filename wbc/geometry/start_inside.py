"""A robot that starts inside a solid in 3-D, said in one line per solid.

The arm obstacle rows (``wbc.laws.constraints.arm_obstacles``) ask d' >= -eta max(d - d_safe, 0)
of each part's distance d from each solid: a part inside one (d < 0) may come no deeper, but
no row pushes it out. So the part moves only outwards or along the solid, and where the task
asks for motion deeper in, that motion is held: the robot may stop short of its goal.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from wbc.geometry.arm_clearance import part_clearances
from wbc.geometry.obstacles3d import Solid
from wbc.robot import MobileManipulator

CONSEQUENCE = (
    "the arm obstacle rows let no part inside go deeper but cannot push one out: "
    "each moves only outwards or along the solid, and the robot may stop short of "
    "its goal"
)
"""What the robot will do, the same for every solid."""


def inside_at_start(
    robot: MobileManipulator, q: np.ndarray, solids: Sequence[Solid], labels: Sequence[str]
) -> tuple[str, ...]:
    """One line for each solid (named by its ``labels`` entry) that a collision part of the
    robot at ``q`` is inside: the deepest part, how deep, and what the robot will do."""
    if not solids or not robot.collision.names:
        return ()
    clearances = part_clearances(robot, np.asarray(q, dtype=float), solids)
    lines = []
    for label, column in zip(labels, clearances.T, strict=True):
        deepest = int(np.argmin(column))
        if column[deepest] < 0.0:
            parts = [robot.collision.names[i] for i in np.flatnonzero(column < 0.0)]
            lines.append(
                f"the robot starts inside {label}: its {', '.join(parts)} "
                f"(the {robot.collision.names[deepest]} {-column[deepest]:.3f} m "
                f"deep); {CONSEQUENCE}"
            )
    return tuple(lines)
