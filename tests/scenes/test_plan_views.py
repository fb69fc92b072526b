"""The supervisor's plan in the 3-D panel (scenes/plan_views.py), as the views of a ``Viewer``
with the robot description: the way and the candidate's ghost, each read with nothing but its
own schema."""

from __future__ import annotations

from typing import Any

import numpy as np

from messages import topics
from messages.header import Header
from messages.supervisor import SupervisorStatus
from scenes.foxglove_views import MODEL_EVERY, Viewer
from tests.scenes.views_read import (
    ROBOT,
    STAMP_NS,
    chain,
    decode,
    same_pose,
    transforms_of,
    vector,
)


def status(seq: int, **fields: Any) -> SupervisorStatus:
    header = Header(stamp_ns=STAMP_NS + seq, frame="world", seq=seq, source="test")
    return SupervisorStatus(
        header=header,
        phase=fields.pop("phase", "drive"),
        candidate=1,
        plans=1,
        replans=0,
        stalls=0,
        **fields,
    )


def test_the_plan_is_the_way_and_the_candidates_ghost_sent_when_it_changes() -> None:
    viewer, key = Viewer(ROBOT), "sim/supervisor/status"
    q = np.array([0.4, -0.3, 0.5, 0.0, -0.3, 0.2, 0.1, 0.4])
    planned = {
        "candidate_base": tuple(q[:3]),
        "candidate_arm": tuple(q[3:]),
        "way": ((0.1, -0.5), (0.4, -0.3)),
    }
    frames, scene = viewer(topics.SUPERVISOR_STATUS.name, key, status(1, **planned))
    assert scene.channel(key)[0] == f"{key}/scene"
    poses = chain(
        transforms_of(frames),
        ["candidate/base", *(f"candidate/link_{i}" for i in range(6))],
        "world",
    )
    for found, expected in zip(poses[1:], ROBOT.frames(q), strict=True):
        assert same_pose(found, expected)
    update = decode(scene)
    assert [d.get("type") for d in update["deletions"]] == [1]  # ALL: the last plan goes
    way = next(e for e in update["entities"] if e["id"] == "plan/way")
    (line,) = way["lines"]
    assert [vector(p, "xy") for p in line["points"]] == [[0.1, -0.5], [0.4, -0.3]]
    assert {e["frame_id"] for e in update["entities"]} >= {"world", "candidate/link_5"}
    # The same plan again: the frames alone, until its turn comes.
    (again,) = viewer(topics.SUPERVISOR_STATUS.name, key, status(2, **planned))
    assert again.schema_name == "foxglove.FrameTransforms"
    _, refresh = viewer(topics.SUPERVISOR_STATUS.name, key, status(MODEL_EVERY, **planned))
    assert decode(refresh)["entities"]
    # The plan is gone (a re-plan): the scene only deletes.
    (gone,) = viewer(topics.SUPERVISOR_STATUS.name, key, status(MODEL_EVERY + 1, phase="planning"))
    assert "entities" not in decode(gone) and decode(gone)["deletions"]
