"""The URDF generated from a robot description: valid XML that yourdfpy loads, whose forward
kinematics are the model's on random configurations, for every robot of deploy/robots."""

import io
import json
import struct
from pathlib import Path

import numpy as np
import pytest
import yourdfpy
import zenoh
from websockets.sync.client import connect

from parsimony.commands.view import serving
from profiles.profile import load_profile
from ros2.urdf import END_EFFECTOR, URDF_URI, joints, link_name, matrix, planar, urdf
from wbc.robot import BASE_DOF, BaseDescription, MobileManipulator

ROBOTS = sorted(Path("deploy/robots").glob("*.yaml"))


def load(text: str) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(io.StringIO(text), build_scene_graph=True, load_meshes=False)


def check_poses(robot: MobileManipulator, model: yourdfpy.URDF, samples: int = 5) -> None:
    rng = np.random.default_rng(36)
    low = np.where(np.isfinite(robot.q_min), robot.q_min, -np.pi)
    high = np.where(np.isfinite(robot.q_max), robot.q_max, np.pi)
    low[:BASE_DOF], high[:BASE_DOF] = (-2.0, -2.0, -np.pi), (2.0, 2.0, np.pi)
    for _ in range(samples):
        q = rng.uniform(low, high)
        model.update_cfg(dict(zip(robot.joint_names, q[BASE_DOF:], strict=True)))
        base = planar(*q[:BASE_DOF])
        for i, frame in enumerate(robot.frames(q)):
            found = base @ model.get_transform(link_name(i), "base_footprint")
            np.testing.assert_allclose(found, matrix(frame), rtol=0.0, atol=1e-9)
        found = base @ model.get_transform(END_EFFECTOR, "base_footprint")
        np.testing.assert_allclose(found, matrix(robot.fkm(q)), rtol=0.0, atol=1e-9)


@pytest.mark.parametrize("path", ROBOTS, ids=lambda p: p.stem)
def test_urdf_poses_are_the_models(path):
    robot = MobileManipulator.from_yaml(path)
    text = urdf(robot)
    model = load(text)
    assert model.robot.name == robot.name
    assert [j for j in model.actuated_joint_names] == list(robot.joint_names)
    assert model.validate()
    check_poses(robot, model)


def test_prismatic_joints_and_a_camera_frame():
    dh = np.array(
        [
            [0.3, 0.0, -0.4],
            [0.2, 0.0, 0.1],
            [0.0, 0.3, 0.25],
            [np.pi / 2, -np.pi / 2, 0.3],
            [0, 1, 0],
        ]
    )
    base = BaseDescription(height=0.4, body_radius=0.3, velocity_max=np.array([0.5, 0.0, 1.0]))
    robot = MobileManipulator(dh, base, -np.ones(3), np.ones(3), np.ones(3), name="slider")
    camera = np.eye(4)
    camera[:3, 3] = (0.1, 0.0, 0.05)
    model = load(urdf(robot, camera=("camera", 3, camera)))
    assert model.joint_map["q2"].type == "prismatic"
    check_poses(robot, model)
    q = np.zeros(robot.dof)
    model.update_cfg(np.zeros(3))
    expected = matrix(robot.frames(q)[-1]) @ camera
    found = model.get_transform("camera", "base_footprint")
    np.testing.assert_allclose(found, expected, rtol=0.0, atol=1e-12)


def test_joint_transforms_are_yourdfpys():
    robot = MobileManipulator.from_yaml("deploy/robots/open_manipulator_x.yaml")
    model = load(urdf(robot))
    q_arm = np.random.default_rng(1).uniform(robot.q_min[BASE_DOF:], robot.q_max[BASE_DOF:])
    model.update_cfg(q_arm)
    for joint in joints(robot):
        found = model.get_transform(joint.child, joint.parent)
        np.testing.assert_allclose(joint.transform(q_arm), found, rtol=0.0, atol=1e-12)


def test_foxglove_fetches_the_urdf_the_live_view_serves():
    """A WebSocket client asks `parsimony view`'s live view (``serving``) for ``URDF_URI`` as
    Foxglove's URDF panel does (the ``assets`` capability, op ``fetchAsset``, a binary
    fetch-asset response) and gets the file /robot_description carries: the profile's robot's."""
    profile = load_profile(Path("deploy/sim.yaml"))
    robot = MobileManipulator.from_yaml(profile.robot)
    config = zenoh.Config()
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')
    with (
        zenoh.open(config) as session,
        serving(session, profile, [], 0, robot) as (view, _),
        connect(view.address, subprotocols=["foxglove.sdk.v1"]) as client,
    ):
        info = json.loads(client.recv(timeout=30))
        assert "assets" in info["capabilities"]
        client.send(json.dumps({"op": "fetchAsset", "uri": URDF_URI, "requestId": 7}))
        reply = client.recv(timeout=30)
        opcode, request, status, error_length = struct.unpack_from("<BIBI", reply)
        assert (opcode, request, status, error_length) == (4, 7, 0, 0)
        assert reply[10:].decode() == urdf(robot)
