"""The arm's obstacle rows as the constraint forms them (wbc/laws/constraints/arm_obstacles.py:
Python geometry, the wrench form of wbc/geometry/wrench_rows.py) are the rows formed from each
part's Jacobian, J_t of 4.18 and DQ Robotics' line Jacobian, with the distance Jacobians of
wbc/geometry/distance_jacobians.py and the closest points of wbc/geometry/plucker.py; the LP's
commands are then the same, step by step and along the reach over the table."""

from __future__ import annotations

import math

import numpy as np

from profiles.deploy_files import ROBOT_FILE
from studies.gain_sets import TABLE_PARAMS
from tests.wbc.wbc_scenarios import configurations, context
from wbc.geometry.distance_jacobians import (
    line_to_line_distance_jacobian,
    line_to_line_squared_distance,
    point_to_line_distance_jacobian,
    point_to_line_squared_distance,
    point_to_plane_distance,
    point_to_plane_distance_jacobian,
    point_to_point_distance_jacobian,
    point_to_point_squared_distance,
)
from wbc.geometry.obstacles3d import CORNER, EDGE, FACE, SIDE, Cylinder, Plane, Solid
from wbc.geometry.plucker import closest_parameters
from wbc.geometry.robot_primitives import primitive_kinematics
from wbc.geometry.scenarios import DT, TABLE, TABLE_GOAL, TABLE_START
from wbc.laws.constraints.arm_obstacles import SKEW_MIN, ArmObstacles
from wbc.laws.constraints.base import LinearRows
from wbc.laws.kinematic_run import integrate
from wbc.laws.lp_law import LPLaw, default_constraints
from wbc.laws.step_context import StepContext
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
GAIN, MARGIN = 2.0, 0.03
SHELF = Plane((0.0, 0.0, -1.0), -0.45, ((0.3, 0.2), (0.7, 0.2), (0.7, 0.6), (0.3, 0.6)), "shelf")
"""The solid above z = 0.45 over its footprint: a point under it meets its underside."""
SOLIDS = (
    TABLE,
    Cylinder(0.45, 0.05, 0.04, 0.5, "pole"),
    Plane((-1.0, 0.0, 0.0), -0.7, name="wall"),
    Cylinder(0.4, -0.2, 0.05, name="tall pole"),
    SHELF,
)


def around(half_width: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The base within ``half_width`` of (0.05, 0) facing anywhere (``configurations``)."""
    return (0.05 - half_width, -half_width, -np.pi), (0.05 + half_width, half_width, np.pi)


def reference_rows(q: np.ndarray, solids: tuple[Solid, ...]) -> tuple[np.ndarray, np.ndarray]:
    """(matrix, upper) of every pair, from each part's J_t and J_l: the constraint's module
    docstring, spelt out with the distance Jacobians and ``closest_parameters``."""
    parts, model = primitive_kinematics(ROBOT, q), ROBOT.collision
    matrix, upper = [], []
    for solid in solids:
        kinds, indices = solid.nearest(parts.points[:, 1:])
        for i, (kind, index) in enumerate(zip(kinds.tolist(), indices.tolist(), strict=True)):
            point, jacobian = parts.points[i], parts.point_jacobians[i]
            safe = model.points[i].radius + MARGIN
            if kind == FACE:
                face = solid.faces()[index]
                row = point_to_plane_distance_jacobian(jacobian, face)
                distance, limit = point_to_plane_distance(point, face), safe
            elif kind == EDGE:
                edge = solid.edges()[index].line
                row = point_to_line_distance_jacobian(jacobian, point, edge)
                distance, limit = point_to_line_squared_distance(point, edge), safe**2
            elif kind == CORNER:
                corner = np.r_[0.0, solid.corners()[index]]
                row = point_to_point_distance_jacobian(jacobian, point, corner)
                distance, limit = point_to_point_squared_distance(point, corner), safe**2
            else:
                row = point_to_line_distance_jacobian(jacobian, point, solid.axis)
                squared = point_to_line_squared_distance(point, solid.axis)
                distance, limit = squared, (solid.radius + safe) ** 2
                if kind != SIDE:  # the rim: d = hypot(sqrt(D) - R, z - h)
                    beside, above = math.sqrt(squared) - solid.radius, point[3] - solid.height
                    distance, limit = math.hypot(beside, above), safe
                    row = (
                        beside / (2.0 * math.sqrt(squared)) * row + above * jacobian[3]
                    ) / distance
            matrix.append(-row)
            upper.append(GAIN * max(distance - limit, 0.0))
        if isinstance(solid, Cylinder):
            top = math.inf if solid.height is None else solid.height
            lines, low, high, reach = [solid.axis], [-math.inf], [top], solid.radius
        else:
            edges = solid.edges()
            lines, low, high = (
                [e.line for e in edges],
                [e.low for e in edges],
                [e.high for e in edges],
            )
            reach = 0.0
        if not lines:
            continue
        lines = np.array(lines)
        s, t, skew = closest_parameters(parts.lines, lines)
        for i, segment in enumerate(model.segments):
            facing = (
                (skew[i] >= SKEW_MIN**2)
                & (parts.ends[i].min() <= s[i])
                & (s[i] <= parts.ends[i].max())
                & (np.array(low) <= t[i])
                & (t[i] <= np.array(high))
            )
            if not facing.any():
                matrix.append(np.zeros(ROBOT.dof))
                upper.append(math.inf)
                continue
            a = lines[:, 5:8] @ parts.lines[i, 1:4] + lines[:, 1:4] @ parts.lines[i, 5:8]
            with np.errstate(divide="ignore", invalid="ignore"):
                gap = np.where(facing, np.abs(a) / np.sqrt(skew[i]), np.inf)
            other = lines[int(np.argmin(gap))]
            matrix.append(
                -line_to_line_distance_jacobian(parts.line_jacobians[i], parts.lines[i], other)
            )
            squared = line_to_line_squared_distance(parts.lines[i], other)
            upper.append(GAIN * max(squared - (reach + segment.radius + MARGIN) ** 2, 0.0))
    return np.array(matrix), np.array(upper)


def test_the_rows_are_those_of_the_parts_jacobians_near_and_far() -> None:
    """Random states near the solids and far from them (the base up to 3 m away): every row
    equal to the reference, its bound too, and the same rows off."""
    kinds = set()
    for half_width, seed in ((0.3, 1), (3.0, 2)):
        for q in configurations(ROBOT, 150, seed, *around(half_width)):
            rows = ArmObstacles(GAIN, MARGIN).rows(context(ROBOT, q, SOLIDS))
            matrix, upper = reference_rows(q, SOLIDS)
            assert np.array_equal(np.isinf(rows.upper), np.isinf(upper))
            finite = np.isfinite(upper)
            np.testing.assert_allclose(rows.upper[finite], upper[finite], rtol=1e-12, atol=1e-13)
            np.testing.assert_allclose(rows.matrix, matrix, rtol=1e-10, atol=1e-12)
            kinds |= {
                int(k)
                for solid in SOLIDS
                for k in solid.nearest(primitive_kinematics(ROBOT, q).points[:, 1:])[0]
            }
    assert kinds == {0, 1, 2, 3, 4}  # every kind of feature was met


class ReferenceRows:
    """The rows of ``reference_rows`` as a constraint, in place of ArmObstacles."""

    name = "arm_obstacles"

    def rows(self, context: StepContext) -> LinearRows:
        matrix, upper = reference_rows(context.q, context.solids)
        return LinearRows(self.name, matrix, np.full(upper.size, -np.inf), upper)


def reference_law() -> LPLaw:
    constraints = [
        c if not isinstance(c, ArmObstacles) else ReferenceRows()
        for c in default_constraints(TABLE_PARAMS)
    ]
    assert any(isinstance(c, ReferenceRows) for c in constraints)
    return LPLaw(ROBOT, TABLE_PARAMS, constraints=constraints)


def test_the_lp_commands_the_same_u_along_the_reach_over_the_table() -> None:
    """The kinematic loop of the reach over the table with the reference rows, and each of its
    states stepped by the law with the constraint's rows: the same u to the solver's
    tolerance, and the same run."""
    task = PoseTask(ROBOT.fkm(TABLE_GOAL))
    reference = integrate(reference_law(), TABLE_START, task, DT, 1500, obstacles=(TABLE,))
    law = LPLaw(ROBOT, TABLE_PARAMS)
    for q, out in zip(reference.configurations, reference.outputs, strict=True):
        np.testing.assert_allclose(law.step(q, task, DT, (TABLE,)).u, out.u, atol=1e-9)
    run = integrate(LPLaw(ROBOT, TABLE_PARAMS), TABLE_START, task, DT, 1500, obstacles=(TABLE,))
    assert reference.converged and len(run.outputs) == len(reference.outputs)
    np.testing.assert_allclose(run.velocities(), reference.velocities(), atol=1e-9)


def test_the_lp_commands_the_same_u_on_random_states_among_the_solids() -> None:
    """One step from random states near the solids, towards a goal among them, cold: the
    same u with either rows."""
    rng = np.random.default_rng(7)
    for q in configurations(ROBOT, 40, 8, *around(0.3)):
        goal = q + rng.normal(scale=0.3, size=q.size)
        task = PoseTask(ROBOT.fkm(goal))
        ours = LPLaw(ROBOT, TABLE_PARAMS).step(q, task, DT, SOLIDS)
        theirs = reference_law().step(q, task, DT, SOLIDS)
        assert ours.status == theirs.status
        np.testing.assert_allclose(ours.u, theirs.u, atol=1e-9)
