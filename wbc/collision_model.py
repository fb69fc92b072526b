"""The robot's parts that 3-D obstacles must clear: points and segments fixed in its frames.

A robot description may declare (``collision`` in deploy/robots/little_john.yaml)::

    points:   {name, frame, offset [x, y, z] in the frame (default 0), radius}
    segments: {name, frame, axis (x, y or z of the frame), start, end (two point names), radius}

``frame`` i is the i-th pose of ``MobileManipulator.frames``: 0 the base top x_2^0, i the frame
after arm link i (a DH table's frame i; a URDF chain's child link of its i-th movable joint, the
last its tip link). A point is a sphere of ``radius`` round p = translation(x_i (1 + eps
offset / 2)); a segment is the capsule of ``radius`` round the part of the frame's axis line
l_ = l + eps p x l between its two points, which must lie on that line in every
configuration (checked when the robot is built). ``wbc.geometry.robot_primitives`` gives their
Jacobians.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from wbc import dq

Array = np.ndarray

AXES: Mapping[str, Array] = {"x": dq.I_, "y": dq.J_, "z": dq.K_}
"""A segment's axis, as a unit pure quaternion in its frame."""
ON_LINE_TOLERANCE = 1e-9
"""How far (m) a segment's end may lie from its frame's axis line."""


@dataclass(frozen=True)
class CollisionPoint:
    """A sphere of ``radius`` (m) at ``offset`` (m) in frame ``frame``."""

    name: str
    frame: int
    offset: tuple[float, float, float]
    radius: float


@dataclass(frozen=True)
class CollisionSegment:
    """A capsule of ``radius`` (m) on the ``axis`` line of frame ``frame``, from point
    ``start`` to point ``end`` (indices into the points)."""

    name: str
    frame: int
    axis: str
    start: int
    end: int
    radius: float


@dataclass(frozen=True)
class CollisionModel:
    """Every part of the robot that obstacles in 3-D must clear (empty: none)."""

    points: tuple[CollisionPoint, ...] = ()
    segments: tuple[CollisionSegment, ...] = ()

    @property
    def names(self) -> tuple[str, ...]:
        """The points' names, then the segments'."""
        return tuple(p.name for p in self.points) + tuple(s.name for s in self.segments)


def _number(value: object, field: str, low: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
        raise ValueError(f"{field}: expected a finite number, got {value!r}")
    if low is not None and value <= low:
        raise ValueError(f"{field}: expected a number > {low}, got {value!r}")
    return float(value)


def _frame(value: object, field: str, frames: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < frames:
        raise ValueError(f"{field}: expected a frame index 0 to {frames - 1}, got {value!r}")
    return value


def _entries(data: Mapping[str, Any], key: str) -> list[Mapping[str, Any]]:
    entries = data.get(key, [])
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        raise ValueError(f"collision.{key}: expected a list of mappings")
    return entries


def _point(entry: Mapping[str, Any], field: str, frames: int) -> CollisionPoint:
    unknown = set(entry) - {"name", "frame", "offset", "radius"}
    if unknown:
        raise ValueError(f"{field}: unknown fields {sorted(unknown)}")
    offset = entry.get("offset", [0.0, 0.0, 0.0])
    if not isinstance(offset, list) or len(offset) != 3:
        raise ValueError(f"{field}.offset: expected 3 numbers, got {offset!r}")
    return CollisionPoint(
        str(entry.get("name", "")) or field,
        _frame(entry.get("frame"), f"{field}.frame", frames),
        tuple(_number(v, f"{field}.offset") for v in offset),  # type: ignore[arg-type]
        _number(entry.get("radius"), f"{field}.radius", 0.0),
    )


def _segment(
    entry: Mapping[str, Any], field: str, frames: int, names: Sequence[str]
) -> CollisionSegment:
    unknown = set(entry) - {"name", "frame", "axis", "start", "end", "radius"}
    if unknown:
        raise ValueError(f"{field}: unknown fields {sorted(unknown)}")
    if entry.get("axis") not in AXES:
        raise ValueError(f"{field}.axis: expected one of x, y, z, got {entry.get('axis')!r}")
    ends = []
    for key in ("start", "end"):
        if entry.get(key) not in names:
            raise ValueError(
                f"{field}.{key}: expected the name of a point ({', '.join(names)}), "
                f"got {entry.get(key)!r}"
            )
        ends.append(names.index(entry[key]))
    if ends[0] == ends[1]:
        raise ValueError(f"{field}: start and end must be two different points")
    return CollisionSegment(
        str(entry.get("name", "")) or field,
        _frame(entry.get("frame"), f"{field}.frame", frames),
        entry["axis"],
        ends[0],
        ends[1],
        _number(entry.get("radius"), f"{field}.radius", 0.0),
    )


def collision_model(data: object, frames: int) -> CollisionModel:
    """The ``collision`` section of a robot description (None: no parts), for a robot of
    ``frames`` frames; ``ValueError`` naming the field."""
    if data is None:
        return CollisionModel()
    if not isinstance(data, dict) or set(data) - {"points", "segments"}:
        raise ValueError("collision: expected a mapping of `points` and `segments`")
    points = tuple(
        _point(e, f"collision.points[{i}]", frames) for i, e in enumerate(_entries(data, "points"))
    )
    names = [p.name for p in points]
    if len(set(names)) != len(names):
        raise ValueError(f"collision.points: names must differ, got {names}")
    segments = tuple(
        _segment(e, f"collision.segments[{i}]", frames, names)
        for i, e in enumerate(_entries(data, "segments"))
    )
    return CollisionModel(points, segments)


class Kinematic(Protocol):
    dof: int
    q_min: Array
    q_max: Array

    def frames(self, q: Array) -> list[Array]: ...


def check_segments(robot: Kinematic, model: CollisionModel) -> None:
    """``ValueError`` unless each segment's ends lie on its frame's axis line, at the zero
    configuration and at three fixed others across the joint box."""
    rng = np.random.default_rng(0)
    box = [np.zeros(robot.dof)] + [
        rng.uniform(np.maximum(robot.q_min, -2.0), np.minimum(robot.q_max, 2.0)) for _ in range(3)
    ]
    for q in box:
        frames = robot.frames(q)
        points = point_positions(frames, model)
        for index, segment in enumerate(model.segments):
            pose = frames[segment.frame]
            origin, direction = dq.translation(pose)[1:], axis_direction(pose, segment.axis)
            for end in (segment.start, segment.end):
                off = float(np.linalg.norm(np.cross(points[end] - origin, direction)))
                if off > ON_LINE_TOLERANCE:
                    raise ValueError(
                        f"collision.segments[{index}] ({segment.name}): point "
                        f"{model.points[end].name} is {off:.3g} m off the "
                        f"{segment.axis} axis of frame {segment.frame}"
                    )


def axis_direction(pose: Array, axis: str) -> Array:
    """The world direction (3-vector) of the frame's ``axis``: Im(r a r*)."""
    r = pose[:4]
    return dq.qmul(dq.qmul(r, AXES[axis]), dq.qconj(r))[1:]


def offset_pose(point: CollisionPoint) -> Array:
    """1 + eps offset / 2: the point's displacement in its frame."""
    return dq.pose(dq.ONE[:4], point.offset)


def point_positions(frames: Sequence[Array], model: CollisionModel) -> Array:
    """(k, 3) world positions of the model's points, for the frames' poses."""
    return np.array(
        [dq.translation(dq.mul(frames[p.frame], offset_pose(p)))[1:] for p in model.points]
    ).reshape(-1, 3)
