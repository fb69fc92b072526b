"""Vector-field inequalities that keep the robot's collision parts clear of obstacles in 3-D
(Marinho, Adorno et al., T-RO 2019, arXiv 1804.11270, eq. 17-19): for each distance d between
a part and an obstacle, d' >= -eta (d - d_safe), i.e. the row

    -J_d u <= eta max(d - d_safe, 0)

(the max keeps u = 0 feasible when a part starts inside d_safe: it may then not come closer).
The parts are the points and segments of ``robot.collision`` (``wbc.collision_model``), each a
sphere or capsule of radius rho; the obstacles are ``wbc.geometry.obstacles3d``'s. The distances and
their Jacobians are ``wbc.geometry.distance_jacobians``':

    point - face            d = <p, n> - d_pi,       d_safe = rho + margin
    point - edge            D = ||p x l - m||^2,     D_safe = (rho + margin)^2       (squared)
    point - corner          D = ||p - c||^2,         D_safe = (rho + margin)^2       (squared)
    point - cylinder side   D = ||p x l - m||^2,     D_safe = (R + rho + margin)^2   (axis)
    point - cylinder rim    d = sqrt((sqrt(D) - R)^2 + (z - h)^2),  d_safe = rho + margin
    segment - cylinder      D = line to line, axis,  D_safe = (R + rho + margin)^2
    segment - solid's edge  D = line to line, edge,  D_safe = (rho + margin)^2

A point keeps one row per obstacle: on its distance from the feature of the solid nearest it
(``nearest`` of wbc.geometry.obstacles3d: a face, an edge, a corner; a cylinder's side, top or rim),
the Euclidean distance from the solid, continuously differentiable outside it, so a point held at
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

Each row is -J_d = -w^T J for the weights w of its distance's rate
(``wbc.geometry.distance_jacobians``) and its part's Jacobian J, formed as the wrench of w on the
twists of the step's forward pass (``wbc.geometry.wrench_rows``), the task's own: every row of a
step in one product. The geometry of a step (a few points, lines and features) is Python float
arithmetic, where numpy's call overhead outweighs the work: the pairing of the segments with a
table's 8 lines costs 11 us so, 33 us in masked arrays (`parsimony bench`'s states of the reach over
the table, CPU time, one run).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from wbc.geometry.distance_jacobians import (
    Vector,
    line_to_line,
    point_to_line,
    point_to_plane,
    point_to_point,
)
from wbc.geometry.obstacles3d import CORNER, EDGE, FACE, RIM, Cylinder, Edge, Solid
from wbc.geometry.plucker import foot
from wbc.geometry.robot_primitives import PrimitiveKinematics, primitive_kinematics
from wbc.geometry.wrench_rows import line_wrench, point_wrench, wrench_rows
from wbc.laws.constraints.base import LinearRows, no_rows
from wbc.laws.gains import gain
from wbc.laws.step_context import StepContext

Array = np.ndarray

SKEW_MIN = 0.1
"""sin of the least angle between a segment and a line for a line-to-line row (5.7 degrees):
the row's Jacobian grows as 1 / sin^2."""


@dataclass(frozen=True)
class ArmObstacleGains:
    arm_obstacles: bool = gain(
        True,
        doc="keep the robot's collision parts clear of the obstacles in 3-D "
        "(wbc.laws.constraints.arm_obstacles; no rows where there are none)",
    )
    arm_obstacle_gain: float = gain(
        2.0, low=1e-3, high=100.0, doc="eta of d' >= -eta (d - d_safe) for the parts, 1/s"
    )
    arm_obstacle_margin: float = gain(
        0.03,
        low=0.0,
        high=0.5,
        doc="clearance kept between a part's surface and an obstacle in 3-D, m",
    )


@dataclass(frozen=True)
class Features:
    """What a solid holds a part from, as Python floats: its faces (vec8 planes), corners
    (x, y, z) and lines (vec8: a cylinder's axis, a footprint's edges), each line's extent
    [low, high] along itself and the radius round it (a cylinder's, 0 for an edge); and
    ``pairing``, whose product with a robot's line gives the terms of its closest points to
    each of the lines (``_Rows.add_segments``)."""

    faces: tuple[Vector, ...]
    corners: tuple[Vector, ...]
    lines: tuple[Vector, ...]
    low: tuple[float, ...]
    high: tuple[float, ...]
    reach: tuple[float, ...]
    pairing: Array
    """(9, 4 k): [l, m, p] (p = l x m, the robot line's foot) times it gives, for each of the
    k lines l_z + eps m_z of foot p_z, the blocks <l, l_z>, <l, m_z> + <m, l_z>, <p, l_z>,
    <l, p_z>."""


@functools.cache
def features(obstacle: Solid) -> Features:
    """A cylinder's axis up to its top, or a footprint's edges and corners
    (``wbc.geometry.obstacles3d``)."""
    if isinstance(obstacle, Cylinder):
        top = math.inf if obstacle.height is None else obstacle.height
        edges, reach, corners = [Edge(obstacle.axis, -math.inf, top)], obstacle.radius, ()
    else:
        edges, reach = list(obstacle.edges()), 0.0
        corners = tuple(map(tuple, obstacle.corners().tolist())) if obstacle.footprint else ()
    lines = np.array([e.line for e in edges]).reshape(-1, 8)
    zero = np.zeros((3, len(edges)))
    directions, moments, feet = lines[:, 1:4].T, lines[:, 5:8].T, foot(lines).T
    pairing = np.block(
        [
            [directions, moments, zero, feet],
            [zero, directions, zero, zero],
            [zero, zero, directions, zero],
        ]
    )
    return Features(
        tuple(tuple(f.tolist()) for f in obstacle.faces()),
        corners,
        tuple(map(tuple, lines.tolist())),
        tuple(e.low for e in edges),
        tuple(e.high for e in edges),
        (reach,) * len(edges),
        pairing,
    )


class ArmObstacles:
    """-J_d u <= eta max(d - d_safe, 0) for each (collision part, obstacle in 3-D) pair (the
    VFI of the module's docstring)."""

    name = "arm_obstacles"

    gains: ClassVar[tuple[type, ...]] = (ArmObstacleGains,)
    """The gains this term reads (declared once, there)."""

    @classmethod
    def of(cls, params: Any) -> ArmObstacles | None:
        """The term as the law's gains ``params`` ask for it, or None when they turn it off."""
        return (
            cls(params.arm_obstacle_gain, params.arm_obstacle_margin)
            if params.arm_obstacles
            else None
        )

    def __init__(self, gain: float = 2.0, margin: float = 0.03) -> None:
        if gain <= 0.0 or margin < 0.0:
            raise ValueError("arm obstacle rows need gain > 0 and margin >= 0")
        self.gain, self.margin = gain, margin

    def rows(self, context: StepContext) -> LinearRows:
        robot, solids = context.robot, context.solids
        model = robot.collision
        if not solids or not (model.points or model.segments):
            return no_rows(self.name, robot.dof)
        rows = _Rows(self, primitive_kinematics(robot, context.q, context.chain))
        for obstacle in solids:
            found = features(obstacle)
            rows.add_points(obstacle, found)
            if found.lines and model.segments:
                rows.add_segments(found)
        return LinearRows(self.name, *rows.stacked())


class _Rows:
    """The rows of one step, in the constraint's order: for each obstacle its points', then
    its segments' (if it has lines). A row that is on is the wrench of its distance's weights
    on its part's frame and the bound eta max(d - d_safe, 0); every such row is multiplied out
    at the end, all in one product (``wbc.geometry.wrench_rows``)."""

    def __init__(self, constraint: ArmObstacles, parts: PrimitiveKinematics) -> None:
        model = parts.robot.collision
        self.gain, self.parts = constraint.gain, parts
        self.safe = [p.radius + constraint.margin for p in model.points]
        self.segment_safe = [s.radius + constraint.margin for s in model.segments]
        self.upper: list[float] = []
        self.on: list[int] = []
        self.wrenches: list[Vector] = []
        self.frames: list[int] = []

    def add(self, distance: float, safe: float, wrench: Vector, frame: int) -> None:
        self.on.append(len(self.upper))
        self.upper.append(self.gain * max(distance - safe, 0.0))
        self.wrenches.append(wrench)
        self.frames.append(frame)

    def add_points(self, obstacle: Solid, found: Features) -> None:
        """Each point's row on the distance from the feature of ``obstacle`` nearest it
        (module docstring); ``found`` are its features."""
        parts = self.parts
        kinds, indices = obstacle.nearest(parts.positions)
        for i, (point, kind, index) in enumerate(
            zip(parts.positions, kinds.tolist(), indices.tolist(), strict=True)
        ):
            safe = self.safe[i]
            if kind == FACE:
                distance, weights = point_to_plane(point, found.faces[index])
            elif kind == CORNER:
                distance, weights = point_to_point(point, found.corners[index])
                safe *= safe
            elif kind == EDGE:
                distance, weights = point_to_line(point, found.lines[index])
                safe *= safe
            else:
                assert isinstance(obstacle, Cylinder)
                distance, weights, safe = _pole(point, obstacle, found.lines[0], safe, kind == RIM)
            self.add(distance, safe, point_wrench(point, weights), parts.point_frames[i])

    def add_segments(self, found: Features) -> None:
        """Each segment's line-to-line row against the cylinder's axis or the nearest of the
        solid's edges that it faces (of the solid's ``found`` features; module docstring);
        0 u <= inf for a segment that faces none. The closest points p + s l and p_z + t l_z
        of a segment's line and a line (p and p_z their feet, as in
        ``wbc.geometry.plucker.closest_parameters``) are at
        s = (b e + f) / c and t = (e + b f) / c, with b = <l, l_z>, e = <p, l_z>,
        f = <l, p_z> and c = 1 - b^2 = ||l x l_z||^2 (each foot is orthogonal to its line);
        the distance between the lines is |<l, m_z> + <m, l_z>| / sqrt(c)."""
        parts = self.parts
        count = len(found.lines)
        pairs = (self._segment_lines @ found.pairing).tolist()
        for i, (terms, (low, high)) in enumerate(zip(pairs, self._segment_spans, strict=True)):
            gap, nearest = math.inf, -1
            for j in range(count):
                b = terms[j]
                skew = 1.0 - b * b
                if skew < SKEW_MIN**2:
                    continue
                e, f = terms[2 * count + j], terms[3 * count + j]
                if not low <= (b * e + f) / skew <= high:
                    continue
                if not found.low[j] <= (e + b * f) / skew <= found.high[j]:
                    continue
                between = abs(terms[count + j]) / math.sqrt(skew) - found.reach[j]
                if between < gap:
                    gap, nearest = between, j
            if nearest < 0:
                self.upper.append(math.inf)
                continue
            line = parts.line_list[i]
            distance, weights = line_to_line(line, found.lines[nearest])
            safe = (found.reach[nearest] + self.segment_safe[i]) ** 2
            self.add(distance, safe, line_wrench(line, weights), parts.segment_frames[i])

    @functools.cached_property
    def _segment_lines(self) -> Array:
        """Each segment's line as (l, m, l x m): what ``add_segments`` pairs with every solid's
        lines, the same for all of them."""
        return np.array(
            [(*line[1:4], *line[5:8], *line_foot(line)) for line in self.parts.line_list]
        )

    @functools.cached_property
    def _segment_spans(self) -> list[tuple[float, float]]:
        """Each segment's parameters along its line, lowest first."""
        return [(min(ends), max(ends)) for ends in self.parts.end_list]

    def stacked(self) -> tuple[Array, Array, Array]:
        """(matrix, lower, upper) of every pair's row: -J_d for a row that is on, 0 <= inf for
        one that is off."""
        upper = np.array(self.upper)
        matrix = np.zeros((upper.size, self.parts.robot.dof))
        if self.on:
            matrix[self.on] = -wrench_rows(self.parts.chain, self.wrenches, self.frames)
        return matrix, np.full(upper.size, -np.inf), upper


def line_foot(line: Vector) -> Vector:
    """l x m: the point of the line l + eps m (vec8) nearest the origin, as (x, y, z)."""
    lx, ly, lz, mx, my, mz = (line[i] for i in (1, 2, 3, 5, 6, 7))
    return (ly * mz - lz * my, lz * mx - lx * mz, lx * my - ly * mx)


def _pole(
    point: Vector, pole: Cylinder, axis: Vector, safe: float, rim: bool
) -> tuple[float, Vector, float]:
    """(distance, weights, safe) beside a cylinder: its side, the squared distance D from the
    axis held from (R + safe)^2; its rim, d = sqrt((sqrt(D) - R)^2 + (z - h)^2) held from
    safe, whose weights are the chain rule of the two,
    w = ((sqrt(D) - R) w_D / (2 sqrt(D)) + (z - h) k) / d."""
    squared, weights = point_to_line(point, axis)
    if not rim:
        return squared, weights, (pole.radius + safe) ** 2
    assert pole.height is not None
    radial = math.sqrt(squared)
    beside, above = radial - pole.radius, point[2] - pole.height
    distance = math.hypot(beside, above)
    scale = beside / (2.0 * radial * distance)
    return (
        distance,
        (scale * weights[0], scale * weights[1], scale * weights[2] + above / distance),
        safe,
    )
