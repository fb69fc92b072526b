"""Poses as Foxglove's FrameTransform (scenes/foxglove_frames.py), read back with nothing but
the schema the view carries."""

from __future__ import annotations

import math

import pytest

from scenes.foxglove_frames import planar_transform, pose_transform, replacing, timestamp
from scenes.foxglove_views import view
from tests.scenes.views_read import STAMP_NS, decode, pose_dq, vector


def test_a_planar_pose_turns_about_z_on_the_floor_at_its_stamp() -> None:
    read = decode(view(planar_transform("world", "base", (1.0, -2.0, math.pi / 2), STAMP_NS)))
    assert (read["parent_frame_id"], read["child_frame_id"]) == ("world", "base")
    assert read["timestamp"] == {"seconds": STAMP_NS // 10**9, "nanos": STAMP_NS % 10**9}
    assert vector(read["translation"], "xyz") == [1.0, -2.0, 0.0]
    assert vector(read["rotation"], "xyzw") == pytest.approx([0, 0, math.sqrt(0.5), math.sqrt(0.5)])


def test_a_dual_quaternion_gives_its_translation_and_rotation() -> None:
    read = decode(view(pose_transform("world", "tool", pose_dq(math.pi, (0.1, 0.2, 0.3)), 5)))
    assert read["timestamp"] == {"nanos": 5}
    assert vector(read["translation"], "xyz") == pytest.approx([0.1, 0.2, 0.3])
    assert vector(read["rotation"], "xyzw") == pytest.approx([0, 0, 1, 0], abs=1e-12)


def test_a_replacing_update_deletes_everything_drawn_before() -> None:
    read = decode(view(replacing(timestamp(STAMP_NS), [])))
    assert [d.get("type") for d in read["deletions"]] == [1]  # ALL
    assert "entities" not in read
