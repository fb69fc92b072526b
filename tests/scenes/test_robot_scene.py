"""The robot drawn from its description (scenes.robot_scene), the markers on the image
(scenes.marker_annotations) and the supervisor's plan (scenes.plan_views), as the views of a
``Viewer`` with the robot description: each read with nothing but its own schema."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from messages import topics
from messages.header import Header
from messages.markers import MarkerDetection, MarkerDetections
from messages.supervisor import SupervisorStatus
from record.session_file import SessionWriter
from record.session_reader import info
from scenes.foxglove_views import MODEL_EVERY, Viewer
from tests.scenes.views_read import (
    KEY,
    ROBOT,
    STAMP_NS,
    chain,
    decode,
    pose_dq,
    robot_state,
    transforms_of,
    vector,
)


def same_pose(a: np.ndarray, b: np.ndarray) -> bool:
    """The same pose (a unit dual quaternion and its negation are one)."""
    return bool(np.allclose(a, b, atol=1e-12) or np.allclose(a, -b, atol=1e-12))


def test_with_the_robot_description_every_link_is_a_frame_of_the_kinematics() -> None:
    viewer = Viewer(ROBOT)
    state = robot_state(seq=1)
    (view,) = viewer(topics.ROBOT_STATE.name, KEY, state)  # the model waits for its turn
    frames = transforms_of(view)
    links = [f"estimate/link_{i}" for i in range(ROBOT.arm_dof + 1)]
    poses = chain(frames, ["estimate/base", *links], "world")
    for found, expected in zip(
        poses[1:], ROBOT.frames(np.array(state.configuration())), strict=True
    ):
        assert same_pose(found, expected)
    assert frames["estimate/end_effector"]["parent_frame_id"] == "world"


def test_the_model_goes_with_one_state_in_model_every() -> None:
    viewer = Viewer(ROBOT)
    counts = [
        len(viewer(topics.ROBOT_STATE.name, KEY, robot_state(seq)))
        for seq in range(2 * MODEL_EVERY)
    ]
    assert [seq for seq, n in enumerate(counts) if n == 2] == [0, MODEL_EVERY]
    frames, model = viewer(topics.ROBOT_STATE.name, KEY, robot_state(0))
    assert model.channel(KEY)[0] == f"{KEY}/model"
    assert model.schema_name == "foxglove.SceneUpdate"
    entities = decode(model)["entities"]
    drawn = {e["frame_id"] for e in entities}
    assert drawn == {"estimate/base", *(f"estimate/link_{i}" for i in range(1, 6))}
    assert all(e["frame_locked"] for e in entities)
    # Each link's line runs from the joint before it to its own origin, in its own frame.
    link_2 = next(e for e in entities if e["id"] == "estimate/link_2")
    (line,) = link_2["lines"]
    points = [vector(p, "xyz") for p in line["points"]]
    assert points[-1] == [0.0, 0.0, 0.0]
    assert np.allclose(points[0], ROBOT.link_outline(2)[0])


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


def test_each_marker_is_its_outline_and_id_on_the_image() -> None:
    camera = Header(stamp_ns=STAMP_NS, frame="camera", seq=3, source="test")
    corners = ((100.5, 50.25), (140.0, 52.0), (138.0, 90.0), (99.0, 88.5))
    seen = (
        MarkerDetection(
            id=3, pose=pose_dq(0.0, (0.1, 0.2, 2.5)), reprojection_error=0.3, corners=corners
        ),
        MarkerDetection(
            id=7,
            pose=pose_dq(0.0, (0.4, 0.0, 2.4)),
            reprojection_error=0.5,
            corners=tuple((u + 200, v) for u, v in corners),
        ),
    )
    key = "sim/vision/markers"
    _, view = Viewer()(
        topics.VISION_MARKERS.name, key, MarkerDetections(header=camera, markers=seen)
    )
    assert view.channel(key)[0] == f"{key}/annotations"
    assert view.schema_name == "foxglove.ImageAnnotations"
    annotations = decode(view)
    assert len(annotations["points"]) == len(annotations["texts"]) == 2
    outline = annotations["points"][0]
    assert outline["type"] == 2  # LINE_LOOP
    assert [vector(p, "xy") for p in outline["points"]] == [list(c) for c in corners]
    assert outline["timestamp"] == {"seconds": STAMP_NS // 10**9, "nanos": STAMP_NS % 10**9}
    assert [t["text"] for t in annotations["texts"]] == ["id 3", "id 7"]
    # A frame without markers clears the last one's annotations.
    (empty,) = Viewer()(topics.VISION_MARKERS.name, key, MarkerDetections(header=camera))
    assert set(decode(empty)) == {"timestamp"}


def test_a_session_written_with_the_robot_draws_it(tmp_path: Path) -> None:
    path = tmp_path / "session.mcap"
    with SessionWriter(path, viewer=Viewer(ROBOT)) as writer:
        for seq in range(MODEL_EVERY + 1):
            writer.write(KEY, robot_state(seq), views=True)
    channels = {c["key"]: c for c in info(path)["channels"]}
    assert channels[f"{KEY}/foxglove"]["messages"] == MODEL_EVERY + 1
    assert channels[f"{KEY}/model"]["messages"] == 2
    assert channels[f"{KEY}/model"]["schema"] == "foxglove.SceneUpdate"
    assert channels[KEY]["topic"] == topics.ROBOT_STATE.name
