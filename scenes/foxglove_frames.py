"""Poses as Foxglove's well-known ``FrameTransform``: a planar pose (x, y, phi) and a unit dual
quaternion (``wbc.dq``), stamped in ns."""

from __future__ import annotations

import math

import numpy as np
from foxglove import messages as fox

from wbc import dq


def timestamp(stamp_ns: int) -> fox.Timestamp:
    return fox.Timestamp(stamp_ns // 1_000_000_000, stamp_ns % 1_000_000_000)


def replacing(stamp: fox.Timestamp, entities: list[fox.SceneEntity]) -> fox.SceneUpdate:
    """A scene update that deletes every entity its topic drew before, then draws
    ``entities``."""
    deletion = fox.SceneEntityDeletion(timestamp=stamp, type=fox.SceneEntityDeletionType.All)
    return fox.SceneUpdate(deletions=[deletion], entities=entities)


def planar_transform(
    parent: str, child: str, base_pose: tuple[float, ...], stamp_ns: int
) -> fox.FrameTransform:
    """The transform of a planar pose (x, y, phi): translation (x, y, 0), phi about z."""
    x, y, phi = base_pose
    return fox.FrameTransform(
        timestamp=timestamp(stamp_ns),
        parent_frame_id=parent,
        child_frame_id=child,
        translation=fox.Vector3(x=float(x), y=float(y), z=0.0),
        rotation=fox.Quaternion(x=0.0, y=0.0, z=math.sin(phi / 2), w=math.cos(phi / 2)),
    )


def pose_transform(
    parent: str, child: str, pose: tuple[float, ...] | np.ndarray, stamp_ns: int
) -> fox.FrameTransform:
    """The transform of a unit dual quaternion: its translation and rotation."""
    x = np.asarray(pose, dtype=float)
    t, r = dq.translation(x), dq.rotation(x)
    return fox.FrameTransform(
        timestamp=timestamp(stamp_ns),
        parent_frame_id=parent,
        child_frame_id=child,
        translation=fox.Vector3(x=float(t[1]), y=float(t[2]), z=float(t[3])),
        rotation=fox.Quaternion(w=float(r[0]), x=float(r[1]), y=float(r[2]), z=float(r[3])),
    )
