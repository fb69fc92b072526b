"""Vector-field inequalities that keep the robot's collision parts clear of obstacles in 3-D
(Marinho, Adorno et al., T-RO 2019, arXiv 1804.11270, eq. 17-19): for each distance d between
a part and an obstacle, d' >= -eta (d - d_safe), i.e. the row

    -J_d u <= eta max(d - d_safe, 0)

(the max keeps u = 0 feasible when a part starts inside d_safe: it may then not come closer).
The parts are the points and segments of ``robot.collision`` (``wbc.collision_model``), each a
sphere or capsule of radius rho; the obstacles are ``wbc.obstacles3d``'s. The distances and
their Jacobians are ``wbc.distance_jacobians``':

    point - face            d = <p, n> - d_pi,       d_safe = rho + margin
    point - edge            D = ||p x l - m||^2,     D_safe = (rho + margin)^2       (squared)
    point - corner          D = ||p - c||^2,         D_safe = (rho + margin)^2       (squared)
    point - cylinder side   D = ||p x l - m||^2,     D_safe = (R + rho + margin)^2   (axis)
    point - cylinder rim    d = sqrt((sqrt(D) - R)^2 + (z - h)^2),  d_safe = rho + margin
    segment - cylinder      D = line to line, axis,  D_safe = (R + rho + margin)^2
    segment - solid's edge  D = line to line, edge,  D_safe = (rho + margin)^2

A point keeps one row per obstacle: on its distance from the feature of the solid nearest it
(``nearest`` of wbc.obstacles3d: a face, an edge, a corner; a cylinder's side, top or rim), the
Euclidean distance from the solid, continuously differentiable outside it, so a point held at
a table's rim slides round it (on the largest face distance alone it stalls there). Inside, the
face it is least deep behind. Planes bound a segment by its ends, which are points. Across a
cylinder's axis or a table's rim or corner the segment's middle can come closer than either end:
a row on
the squared distance between its line and that line holds when their closest points lie inside
both (the segment, the edge's extent, the cylinder's height) and they are not nearly parallel
(sin of their angle >= ``SKEW_MIN``; nearer parallel, the ends' rows bound the segment within
length * ``SKEW_MIN``); else the row is off (0 u <= inf). Of a solid's edges, the nearest such
is kept. So every (part, obstacle) pair has one row, whatever the state: the LP keeps its shape.
Not guarded: a segment cutting the rim of a cylinder's top, both ends clear of it.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc.constraints.base import LinearRows
from wbc.distance_jacobians import (
    line_to_line_distance_jacobian,
    line_to_line_squared_distance,
    point_to_line_distance_jacobian,
    point_to_line_squared_distance,
    point_to_plane_distance,
    point_to_plane_distance_jacobian,
    point_to_point_distance_jacobian,
    point_to_point_squared_distance,
)
from wbc.gains import gain
from wbc.obstacles3d import CORNER, EDGE, FACE, RIM, SIDE, Cylinder, Edge, Plane, Solid
from wbc.plucker import closest_parameters
from wbc.robot_primitives import PrimitiveKinematics, primitive_kinematics
from wbc.step_context import StepContext

Array = np.ndarray

SKEW_MIN = 0.1
"""sin of the least angle between a segment and a line for a line-to-line row (5.7 degrees):
the row's Jacobian grows as 1 / sin^2."""


@dataclass(frozen=True)
class ArmObstacleGains:
    arm_obstacles: bool = gain(
        True, doc="keep the robot's collision parts clear of the obstacles in 3-D "
                  "(wbc.constraints.arm_obstacles; no rows where there are none)")
    arm_obstacle_gain: float = gain(2.0, low=1e-3, high=100.0,
                                    doc="eta of d' >= -eta (d - d_safe) for the parts, 1/s")
    arm_obstacle_margin: float = gain(0.03, low=0.0, high=0.5,
                                      doc="clearance kept between a part's surface and an "
                                          "obstacle in 3-D, m")


@functools.cache
def _faces(obstacle: Solid) -> Array:
    """The faces (k, 8) of ``obstacle`` (``faces``)."""
    return np.array(obstacle.faces()).reshape(-1, 8)


@functools.cache
def _corners(obstacle: Plane) -> Array:
    """The corners (k, 4) of ``obstacle`` as pure quaternions (``Plane.corners``)."""
    return np.hstack((np.zeros((len(obstacle.footprint), 1)), obstacle.corners()))


@dataclass(frozen=True)
class Lines:
    """The lines a segment is held from, of one obstacle: Plücker lines (k, 8), the extent
    [low, high] of each along itself, and the radius round each (a cylinder's, 0 for an
    edge)."""

    lines: Array
    low: Array
    high: Array
    reach: Array


@functools.cache
def lines_of(obstacle: Solid) -> Lines:
    """A cylinder's axis up to its top, or a footprint's edges (``wbc.obstacles3d``)."""
    if isinstance(obstacle, Cylinder):
        top = math.inf if obstacle.height is None else obstacle.height
        edges, reach = [Edge(obstacle.axis, -math.inf, top)], obstacle.radius
    else:
        edges, reach = list(obstacle.edges()), 0.0
    return Lines(np.array([e.line for e in edges]).reshape(-1, 8),
                 np.array([e.low for e in edges]), np.array([e.high for e in edges]),
                 np.full(len(edges), reach))  # fmt: skip


class ArmObstacles:
    """-J_d u <= eta max(d - d_safe, 0) for each (collision part, obstacle in 3-D) pair (the
    VFI of the module's docstring)."""

    name = "arm_obstacles"

    gains: ClassVar[tuple[type, ...]] = (ArmObstacleGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> ArmObstacles | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        return cls(params.arm_obstacle_gain, params.arm_obstacle_margin) \
            if params.arm_obstacles else None  # fmt: skip

    def __init__(self, gain: float = 2.0, margin: float = 0.03) -> None:
        if gain <= 0.0 or margin < 0.0:
            raise ValueError("arm obstacle rows need gain > 0 and margin >= 0")
        self.gain, self.margin = gain, margin

    def rows(self, context: StepContext) -> LinearRows:
        robot, solids = context.robot, context.solids
        model = robot.collision
        if not solids or not model.names:
            empty = np.zeros(0)
            return LinearRows(self.name, np.zeros((0, robot.dof)), empty, empty, engaged=False)
        parts = primitive_kinematics(robot, context.q)
        safe = np.array([p.radius for p in model.points]) + self.margin
        matrices, uppers = [], []
        for obstacle in solids:
            matrix, upper = self._point_rows(parts, safe, obstacle)
            matrices.append(matrix)
            uppers.append(upper)
            if len(lines_of(obstacle).lines) and model.segments:
                matrix, upper = self._segment_rows(parts, obstacle, context)
                matrices.append(matrix)
                uppers.append(upper)
        upper = np.concatenate(uppers)
        return LinearRows(self.name, np.vstack(matrices), np.full(upper.size, -np.inf), upper)

    def _point_rows(self, parts: PrimitiveKinematics, safe: Array, obstacle: Solid
                    ) -> tuple[Array, Array]:  # fmt: skip
        """Each point's row on the distance from the feature of ``obstacle`` nearest it
        (module docstring), and its bound; ``safe`` is each point's radius plus the margin.
        The points are taken kind by kind, each kind's distance once for all of its points."""
        points, jacobians = parts.points, parts.point_jacobians
        kind, index = obstacle.nearest(points[:, 1:])
        rows, upper = np.empty((len(points), jacobians.shape[2])), np.empty(len(points))
        faces = kind == FACE
        if faces.any():
            face = _faces(obstacle)[index[faces]]
            rows[faces] = -point_to_plane_distance_jacobian(jacobians[faces], face)
            upper[faces] = point_to_plane_distance(points[faces], face) - safe[faces]
        edges = kind == EDGE
        if edges.any():
            edge = lines_of(obstacle).lines[index[edges]]
            rows[edges] = -point_to_line_distance_jacobian(jacobians[edges], points[edges], edge)
            upper[edges] = (point_to_line_squared_distance(points[edges], edge)
                            - safe[edges] ** 2)  # fmt: skip
        corners = kind == CORNER
        if corners.any():
            corner = _corners(obstacle)[index[corners]]
            rows[corners] = -point_to_point_distance_jacobian(jacobians[corners],
                                                              points[corners], corner)
            upper[corners] = (point_to_point_squared_distance(points[corners], corner)
                              - safe[corners] ** 2)  # fmt: skip
        pole = (kind == SIDE) | (kind == RIM)
        if pole.any():
            rows[pole], upper[pole] = self._pole_rows(points[pole], jacobians[pole], safe[pole],
                                                      obstacle, kind[pole] == RIM)  # fmt: skip
        return rows, self.gain * np.maximum(upper, 0.0)

    @staticmethod
    def _pole_rows(points: Array, jacobians: Array, safe: Array, pole: Cylinder, rim: Array
                   ) -> tuple[Array, Array]:  # fmt: skip
        """Rows and distances less the safe ones beside a cylinder: its side, the squared
        distance D from the axis held from (R + safe)^2; its rim, d = sqrt((sqrt(D) - R)^2 +
        (z - h)^2) held from safe, whose row is the chain rule of the two,
        J_d = ((sqrt(D) - R) J_D / (2 sqrt(D)) + (z - h) J_z) / d."""
        squared = point_to_line_squared_distance(points, pole.axis)
        rows = -point_to_line_distance_jacobian(jacobians, points, pole.axis)
        gaps = squared - (pole.radius + safe) ** 2
        if rim.any():
            radial = np.sqrt(squared[rim])
            beside, above = radial - pole.radius, points[rim, 3] - pole.height
            distance = np.hypot(beside, above)
            rows[rim] = (beside / (2.0 * radial))[:, None] * rows[rim]
            rows[rim] -= above[:, None] * jacobians[rim, 3]
            rows[rim] /= distance[:, None]
            gaps[rim] = distance - safe[rim]
        return rows, gaps

    def _segment_rows(self, parts: PrimitiveKinematics, obstacle: Solid, context: StepContext
                      ) -> tuple[Array, Array]:  # fmt: skip
        """Each segment's line-to-line row against the cylinder's axis or the nearest of the
        solid's edges that it faces (module docstring), and its bound; 0 u <= inf for a
        segment that faces none."""
        found = lines_of(obstacle)
        s, t, skew = closest_parameters(parts.lines, found.lines)  # (segments, lines)
        a = parts.lines[:, 1:4] @ found.lines[:, 5:8].T + parts.lines[:, 5:8] @ found.lines[
            :, 1:4].T  # fmt: skip
        facing = ((skew >= SKEW_MIN**2) & (parts.ends.min(axis=1)[:, None] <= s)
                  & (s <= parts.ends.max(axis=1)[:, None]) & (found.low <= t)
                  & (t <= found.high))  # fmt: skip
        with np.errstate(divide="ignore", invalid="ignore"):
            gap = np.where(facing, np.abs(a) / np.sqrt(skew) - found.reach, np.inf)
        segments = context.robot.collision.segments
        matrix, upper = np.zeros((len(segments), context.robot.dof)), np.full(len(segments),
                                                                              np.inf)
        for i in np.flatnonzero(facing.any(axis=1)):
            nearest = int(np.argmin(gap[i]))
            other, reach = found.lines[nearest], float(found.reach[nearest])
            line = parts.lines[i]
            matrix[i] = -line_to_line_distance_jacobian(parts.line_jacobians[i], line, other)
            squared = line_to_line_squared_distance(line, other)
            upper[i] = self._bound(squared, (reach + segments[i].radius + self.margin) ** 2)
        return matrix, upper

    def _bound(self, distance: float, safe: float) -> float:
        return self.gain * max(distance - safe, 0.0)
