"""The robot scene (scenes.robot_scene) of every robot of the zoo, and of a prismatic joint:
its frames are the robot's kinematics, its model has a link per joint and the base's wheels
by its kind, and a state of another robot is refused naming both robots' joints."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from messages import topics
from messages.header import Header
from messages.state import RobotState
from profiles.deploy_files import ROBOT_FILE, zoo
from scenes.foxglove_views import ESTIMATE_COLOR, Viewer
from scenes.robot_scene import RobotDrawing
from tests.robot_states import state_at
from tests.scenes.views_read import KEY, STAMP_NS, chain, decode, transforms_of, vector
from wbc import dq
from wbc.robot import MobileManipulator

ZOO = zoo()
WHEELS = {"differential": 2, "omnidirectional": 4, "fixed": 0}


def state_of(robot: MobileManipulator, q: np.ndarray) -> RobotState:
    return state_at(robot, q, Header(stamp_ns=STAMP_NS, frame="world", seq=0, source="test"))


def inside(robot: MobileManipulator, seed: int = 0) -> np.ndarray:
    """A configuration inside the joint limits, the base somewhere on the floor."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1.0, 1.0, robot.dof)
    low, high = robot.q_min[3:], robot.q_max[3:]
    q[3:] = low + (high - low) * rng.uniform(0.1, 0.9, robot.arm_dof)
    return q


def same_pose(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.allclose(a, b, atol=1e-9) or np.allclose(a, -b, atol=1e-9))


@pytest.mark.parametrize("path", ZOO, ids=[p.stem for p in ZOO])
def test_each_robot_of_the_zoo_is_drawn_from_its_description(path: Path) -> None:
    robot = MobileManipulator.from_yaml(path)
    q = inside(robot)
    frames_view, model_view = Viewer(robot)(topics.ROBOT_STATE.name, KEY, state_of(robot, q))
    frames = transforms_of(frames_view)
    links = [f"estimate/link_{i}" for i in range(robot.arm_dof + 1)]
    poses = chain(frames, ["estimate/base", *links], "world")
    for found, expected in zip(poses[1:], robot.frames(q), strict=True):
        assert same_pose(found, expected)
    entities = decode(model_view)["entities"]
    assert {e["frame_id"] for e in entities} == {"estimate/base", *links[1:]}
    (base,) = [e for e in entities if e["id"] == "estimate/base"]
    assert len(base["cylinders"]) == 1 + WHEELS[robot.base.kind]  # the body, the wheels


def test_a_state_of_another_robot_is_refused_naming_both_robots_joints() -> None:
    other = MobileManipulator.from_yaml(ROBOT_FILE.parent / "open_manipulator_x.yaml")
    drawing = RobotDrawing(MobileManipulator.from_yaml(ROBOT_FILE), "estimate/", ESTIMATE_COLOR)
    with pytest.raises(ValueError, match="joint1, joint2, joint3, joint4; the robot descr.*q1"):
        drawing.configuration(state_of(other, inside(other)))


def test_a_prismatic_link_is_its_rail_and_a_carriage_that_runs_along_it(tmp_path: Path) -> None:
    description = yaml.safe_load(ROBOT_FILE.read_text())
    description["arm"]["dh"]["type"][1] = "prismatic"
    description["arm"]["joint_min"][1], description["arm"]["joint_max"][1] = 0.05, 0.25
    path = tmp_path / "slider.yaml"
    path.write_text(yaml.safe_dump(description))
    robot = MobileManipulator.from_yaml(path)
    q = inside(robot)
    frames_view, model_view = Viewer(robot)(topics.ROBOT_STATE.name, KEY, state_of(robot, q))
    links = [f"estimate/link_{i}" for i in range(robot.arm_dof + 1)]
    poses = chain(transforms_of(frames_view), ["estimate/base", *links], "world")
    for found, expected in zip(poses[1:], robot.frames(q), strict=True):
        assert same_pose(found, expected)
    entities = {e["id"]: e for e in decode(model_view)["entities"]}
    rail = entities["estimate/link_2_rail"]
    assert rail["frame_id"] == "estimate/link_1"  # fixed in the frame before the joint
    points = np.array([vector(p, "xyz") for p in rail["lines"][0]["points"]])
    for end, limit in zip(points[1:], (0.05, 0.25), strict=True):
        q[4] = limit
        assert np.allclose(end, dq.translation(robot.link_transforms(q)[2])[1:], atol=1e-6)
    assert entities["estimate/link_2"]["frame_id"] == "estimate/link_2"  # the carriage
