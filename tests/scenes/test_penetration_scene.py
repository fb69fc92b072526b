"""The parts of the simulated robot inside a solid, drawn red where they truly are
(scenes/penetration_scene.py), as the view of a ``Viewer`` of the ground truth."""

from __future__ import annotations

import numpy as np

from messages import topics
from messages.obstacles import Plane, Solids
from messages.truth import SimTruth
from scenes.foxglove_views import PENETRATIONS_SUFFIX, Viewer
from tests.scenes.views_read import HEADER, ROBOT, decode, vector, views
from wbc.collision_model import point_positions

TRUTH_KEY = "sim/sim/truth"


def truth(q: np.ndarray, solids: Solids, penetrating: bool, seq: int) -> SimTruth:
    return SimTruth(
        header=HEADER.model_copy(update={"seq": seq}),
        base_pose=tuple(q[:3]),
        arm_joints=tuple(q[3:]),
        end_effector=tuple(ROBOT.fkm(q)),
        contacts=0,
        in_contact=False,
        solids=solids,
        arm_penetrating=penetrating,
    )


def test_a_part_inside_a_solid_is_drawn_red_where_it_truly_is() -> None:
    q = np.array([0.7, -0.4, 0.5, 0.2, -0.6, 0.2, -1.0, 0.4])
    names = ROBOT.collision.names
    parts = point_positions(ROBOT.frames(q), ROBOT.collision)
    gripper = parts[names.index("gripper")]
    # A table top 5 cm over the gripper, a 10 cm square round it: the gripper is inside.
    x, y = gripper[:2]
    table = Plane(
        name="low table",
        normal=(0.0, 0.0, 1.0),
        offset=float(gripper[2]) + 0.05,
        footprint=(
            (x - 0.05, y - 0.05),
            (x + 0.05, y - 0.05),
            (x + 0.05, y + 0.05),
            (x - 0.05, y + 0.05),
        ),
    )
    viewer = Viewer(ROBOT)
    drawn = views(viewer, TRUTH_KEY, topics.SIM_TRUTH, truth(q, Solids(planes=(table,)), True, 1))
    update = decode(drawn[PENETRATIONS_SUFFIX])
    assert [d.get("type") for d in update["deletions"]] == [1]
    (entity,) = update["entities"]
    assert entity["frame_id"] == "truth/world"  # the simulator's world, where the truth stands
    inside = entity["metadata"][0]["value"].split(", ")
    assert "gripper" in inside and "base" not in inside
    centres = [vector(s["pose"]["position"], "xyz") for s in entity["spheres"]]
    assert any(np.allclose(c, gripper) for c in centres)
    colours = {
        tuple(vector(s["color"], "rgba")) for s in [*entity["spheres"], *entity.get("lines", [])]
    }
    assert colours == {(1.0, 0.0, 0.0, 1.0)}  # red
    # Out of it: one empty scene, then nothing until a part goes in again.
    clear = views(viewer, TRUTH_KEY, topics.SIM_TRUTH, truth(q, Solids(), False, 2))
    assert "entities" not in decode(clear[PENETRATIONS_SUFFIX])
    assert PENETRATIONS_SUFFIX not in views(
        viewer, TRUTH_KEY, topics.SIM_TRUTH, truth(q, Solids(), False, 3)
    )
