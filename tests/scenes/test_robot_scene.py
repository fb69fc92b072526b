"""The robot drawn from its description (scenes.robot_scene), as the views of a ``Viewer`` with
the robot description: each read with nothing but its own schema."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from messages import topics
from record.session_file import SessionWriter
from record.session_reader import info
from scenes.foxglove_views import MODEL_EVERY, Viewer
from tests.scenes.views_read import (
    KEY,
    ROBOT,
    chain,
    decode,
    robot_state,
    same_pose,
    transforms_of,
    vector,
)


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
