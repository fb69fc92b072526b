"""The whole-body model (wbc/robot.py): chapter 4 against DQ Robotics and finite differences."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
import yaml
from dqrobotics import E_, k_
from dqrobotics.robot_modeling import (
    DQ_HolonomicBase,
    DQ_Kinematics,
    DQ_SerialManipulatorDH,
    DQ_WholeBody,
)

from profiles.deploy_files import ROBOT_FILE
from tests.wbc.wbc_scenarios import central_difference
from wbc import dq
from wbc.robot import MobileManipulator, RobotDescriptionError, translation_jacobian

ORACLE_TOL = 1e-12
FINITE_DIFFERENCE_TOL = 1e-7


@pytest.fixture(scope="module")
def robot() -> MobileManipulator:
    return MobileManipulator.from_yaml(ROBOT_FILE)


@pytest.fixture(scope="module")
def description() -> dict:
    return yaml.safe_load(ROBOT_FILE.read_text())


@pytest.fixture(scope="module")
def oracle(robot: MobileManipulator) -> DQ_WholeBody:
    """The same robot built from DQ Robotics: holonomic base, height displacement, DH arm."""
    arm = DQ_SerialManipulatorDH(np.array(robot.dh))
    base = DQ_HolonomicBase()
    base.set_frame_displacement(1 + E_ * 0.5 * 0.170 * k_)
    whole_body = DQ_WholeBody(base)
    whole_body.add(arm)
    return whole_body


def random_configurations(robot: MobileManipulator, count: int, seed: int) -> np.ndarray:
    """Base anywhere in a 6 m square facing anywhere; arm joints over their whole servo travel."""
    rng = np.random.default_rng(seed)
    base = rng.uniform([-3.0, -3.0, -np.pi], [3.0, 3.0, np.pi], (count, 3))
    arm = rng.uniform(-2.618, 2.618, (count, robot.arm_dof))
    return np.hstack((base, arm))


# --- Description ------------------------------------------------------------------------------


def test_dh_is_the_yaml_table_and_read_only(robot: MobileManipulator, description: dict) -> None:
    table = description["arm"]["dh"]
    expected = np.array([table["theta"], table["d"], table["a"], table["alpha"], np.zeros(5)])
    assert robot.dh.shape == (5, 5)
    np.testing.assert_array_equal(robot.dh, expected)
    with pytest.raises(ValueError):
        robot.dh[1, 0] = 0.0


def test_base_and_limits_come_from_the_yaml(robot: MobileManipulator, description: dict) -> None:
    arm, base = description["arm"], description["base"]
    assert robot.base_height == 0.170
    assert robot.base.body_radius == 0.165
    assert robot.base.wheel_radius == 0.5 * base["wheel_diameter"]
    assert robot.dof == 8 and robot.arm_dof == 5
    np.testing.assert_array_equal(robot.q_min, [-np.inf] * 3 + arm["joint_min"])
    np.testing.assert_array_equal(robot.q_max, [np.inf] * 3 + arm["joint_max"])
    np.testing.assert_array_equal(robot.velocity_max, base["velocity_max"] + arm["velocity_max"])
    for array in (robot.q_min, robot.q_max, robot.velocity_max):
        with pytest.raises(ValueError):
            array[4] = 0.0


# --- Against DQ Robotics ----------------------------------------------------------------------


def test_fkm_and_pose_jacobian_match_dqrobotics(
    robot: MobileManipulator, oracle: DQ_WholeBody
) -> None:
    for q in random_configurations(robot, 200, seed=1):
        np.testing.assert_allclose(robot.fkm(q), oracle.fkm(q).vec8(), rtol=0, atol=ORACLE_TOL)
        np.testing.assert_allclose(
            robot.pose_jacobian(q), oracle.pose_jacobian(q), rtol=0, atol=ORACLE_TOL
        )


def test_translation_jacobian_matches_dqrobotics(
    robot: MobileManipulator, oracle: DQ_WholeBody
) -> None:
    for q in random_configurations(robot, 200, seed=2):
        pose = oracle.fkm(q)
        expected = DQ_Kinematics.translation_jacobian(oracle.pose_jacobian(q), pose)
        np.testing.assert_allclose(robot.translation_jacobian(q), expected, rtol=0, atol=ORACLE_TOL)
        x, jacobian = robot.kinematics(q)
        np.testing.assert_allclose(
            translation_jacobian(x, jacobian), expected, rtol=0, atol=ORACLE_TOL
        )


# --- Consistency ------------------------------------------------------------------------------


def test_pose_jacobian_is_the_derivative_of_fkm(robot: MobileManipulator) -> None:
    for q in random_configurations(robot, 20, seed=3):
        np.testing.assert_allclose(
            robot.pose_jacobian(q),
            central_difference(robot.fkm, q),
            rtol=0,
            atol=FINITE_DIFFERENCE_TOL,
        )


def test_translation_jacobian_is_the_derivative_of_the_translation(
    robot: MobileManipulator,
) -> None:
    def position(q: np.ndarray) -> np.ndarray:
        return dq.translation(robot.fkm(q))

    for q in random_configurations(robot, 20, seed=4):
        np.testing.assert_allclose(
            robot.translation_jacobian(q),
            central_difference(position, q),
            rtol=0,
            atol=FINITE_DIFFERENCE_TOL,
        )


def test_fkm_is_a_unit_dual_quaternion(robot: MobileManipulator) -> None:
    for q in random_configurations(robot, 50, seed=5):
        x = robot.fkm(q)
        np.testing.assert_allclose(dq.mul(dq.conj(x), x), dq.ONE, rtol=0, atol=1e-12)


def test_kinematics_is_fkm_and_pose_jacobian(robot: MobileManipulator) -> None:
    for q in random_configurations(robot, 20, seed=6):
        x, jacobian = robot.kinematics(q)
        np.testing.assert_allclose(x, robot.fkm(q), rtol=0, atol=1e-14)
        np.testing.assert_array_equal(jacobian, robot.pose_jacobian(q))


def test_base_pose_follows_equation_4_1(robot: MobileManipulator) -> None:
    """With the arm at q_a = 0 the base part moves the pose by x, y and turns it by phi about z."""
    q = np.array([1.0, -2.0, 0.7, 0.0, 0.0, 0.0, 0.0, 0.0])
    at_origin = robot.fkm(np.concatenate(([0.0, 0.0, 0.0], q[3:])))
    base = dq.pose(dq.rotation_quaternion(0.7, [0, 0, 1]), [1.0, -2.0, 0.0])
    np.testing.assert_allclose(robot.fkm(q), dq.mul(base, at_origin), rtol=0, atol=1e-14)


def test_link_points_run_from_the_base_top_to_the_end_effector(robot: MobileManipulator) -> None:
    for q in random_configurations(robot, 20, seed=7):
        points = robot.link_points(q)
        assert points.shape == (robot.arm_dof + 1, 3)
        np.testing.assert_allclose(points[0], [q[0], q[1], robot.base_height], atol=1e-14)
        np.testing.assert_allclose(points[-1], dq.translation(robot.fkm(q))[1:], atol=1e-14)


def test_link_points_at_zero_follow_the_dh_lengths(robot: MobileManipulator) -> None:
    """At q = 0 the arm stands d1 above the base top and stretches along x by a2, d4 and a5."""
    expected = [
        [0.0, 0.0, 0.170],
        [0.0, 0.0, 0.337],
        [0.159, 0.0, 0.337],
        [0.159, 0.0, 0.359250],
        [0.2815, 0.0, 0.359250],
        [0.4515, 0.0, 0.359250],
    ]
    np.testing.assert_allclose(robot.link_points(np.zeros(8)), expected, atol=1e-12)


@pytest.mark.parametrize("shape", [(7,), (9,), (8, 1), (1, 8), ()])
@pytest.mark.parametrize(
    "method", ["fkm", "pose_jacobian", "translation_jacobian", "kinematics", "link_points"]
)
def test_wrong_shape_configuration_raises(
    robot: MobileManipulator, method: str, shape: tuple[int, ...]
) -> None:
    with pytest.raises(ValueError, match="shape"):
        getattr(robot, method)(np.zeros(shape))


# --- Broken descriptions ----------------------------------------------------------------------


def _without(data: dict, path: tuple[str, ...]) -> dict:
    broken = yaml.safe_load(yaml.safe_dump(data))
    node = broken
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]
    return broken


MISSING_FIELDS = [
    ("arm",),
    ("base",),
    ("arm", "dh"),
    ("arm", "dh", "theta"),
    ("arm", "dh", "alpha"),
    ("arm", "dh", "type"),
    ("arm", "joint_min"),
    ("arm", "joint_max"),
    ("arm", "velocity_max"),
    ("base", "height"),
    ("base", "body_radius"),
    ("base", "wheel_base"),
    ("base", "wheel_diameter"),
    ("base", "wheel_speed_max"),
    ("base", "velocity_max"),
]


@pytest.mark.parametrize(
    ("text", "said"),
    [
        (b"arm: [1.0, 2.0\n", ":2:1: not YAML: expected ',' or ']', but got '<stream end>'"),
        (
            b"- arm\n- base\n",
            ": a robot description is a mapping (arm:, base:, ...), this file holds a list",
        ),
        (
            b"little john\n",
            ": a robot description is a mapping (arm:, base:, ...), this file holds a str",
        ),
        (b"", ": a robot description is a mapping (arm:, base:, ...), this file holds nothing"),
        (b"\x89PNG\r\n\x1a\n\xff", ": not UTF-8 text (byte 0)"),
    ],
    ids=["not-yaml", "list", "text", "empty", "binary"],
)
def test_a_file_that_is_no_robot_description_is_one_line_naming_it(
    tmp_path: Path, text: bytes, said: str
) -> None:
    """A ValueError that says what is wrong, as the commands print it (before, YAML's own error
    or 'missing or invalid field: list indices must be integers')."""
    path = tmp_path / "robot.yaml"
    path.write_bytes(text)
    with pytest.raises(RobotDescriptionError) as raised:
        MobileManipulator.from_yaml(path)
    assert str(raised.value) == f"{path}{said}"


@pytest.mark.parametrize("field", MISSING_FIELDS, ids=".".join)
def test_missing_field_names_file_and_field(
    tmp_path: Path, description: dict, field: tuple[str, ...]
) -> None:
    path = tmp_path / "broken_robot.yaml"
    path.write_text(yaml.safe_dump(_without(description, field)))
    with pytest.raises(RobotDescriptionError) as raised:
        MobileManipulator.from_yaml(path)
    message = str(raised.value)
    assert str(path) in message
    assert field[-1] in message


@pytest.mark.parametrize(
    ("field", "value"),
    [
        (("arm", "joint_min"), [-1.0, -1.0, -1.0, -1.0]),
        (("base", "velocity_max"), [0.2, 0.2]),
        (("arm", "joint_max"), [1.0, 1.0, float("nan"), 1.0, 1.0]),
    ],
    ids=["short_joint_min", "short_base_velocity_max", "nan_joint_max"],
)
def test_invalid_field_names_file_and_field(
    tmp_path: Path, description: dict, field: tuple[str, str], value: list[float]
) -> None:
    broken = yaml.safe_load(yaml.safe_dump(description))
    broken[field[0]][field[1]] = value
    path = tmp_path / "invalid_robot.yaml"
    path.write_text(yaml.safe_dump(broken))
    with pytest.raises(RobotDescriptionError) as raised:
        MobileManipulator.from_yaml(path)
    assert str(path) in str(raised.value)
    assert field[1] in str(raised.value)


def _with_prismatic(tmp_path: Path, description: dict) -> MobileManipulator:
    """Little John with its third joint made prismatic (d3 + q3 along z_2)."""
    changed = yaml.safe_load(yaml.safe_dump(description))
    changed["arm"]["dh"]["type"][2] = "prismatic"
    changed["arm"]["dh"]["names"] = ["waist", "shoulder", "slide", "roll", "pitch"]
    path = tmp_path / "prismatic_robot.yaml"
    path.write_text(yaml.safe_dump(changed))
    return MobileManipulator.from_yaml(path)


def test_a_prismatic_dh_joint_matches_dqrobotics(tmp_path: Path, description: dict) -> None:
    """Type 1 of DQ Robotics' DH table: the joint adds q to d; poses and Jacobians agree."""
    robot = _with_prismatic(tmp_path, description)
    assert robot.joint_types == ("revolute", "revolute", "prismatic", "revolute", "revolute")
    assert robot.joint_names == ("waist", "shoulder", "slide", "roll", "pitch")
    arm = DQ_SerialManipulatorDH(np.array(robot.dh))
    base = DQ_HolonomicBase()
    base.set_frame_displacement(1 + E_ * 0.5 * 0.170 * k_)
    oracle = DQ_WholeBody(base)
    oracle.add(arm)
    for q in random_configurations(robot, 100, seed=11):
        np.testing.assert_allclose(robot.fkm(q), oracle.fkm(q).vec8(), rtol=0, atol=ORACLE_TOL)
        np.testing.assert_allclose(
            robot.pose_jacobian(q), oracle.pose_jacobian(q), rtol=0, atol=ORACLE_TOL
        )


def test_a_prismatic_joint_jacobian_is_the_derivative_of_fkm(
    tmp_path: Path, description: dict
) -> None:
    robot = _with_prismatic(tmp_path, description)
    for q in random_configurations(robot, 20, seed=12):
        np.testing.assert_allclose(
            robot.pose_jacobian(q),
            central_difference(robot.fkm, q),
            rtol=0,
            atol=FINITE_DIFFERENCE_TOL,
        )
        _, jacobians = robot.frame_kinematics(q)
        for i in range(robot.arm_dof + 1):
            np.testing.assert_allclose(
                jacobians[i],
                central_difference(lambda q, i=i: robot.frames(q)[i], q),
                rtol=0,
                atol=FINITE_DIFFERENCE_TOL,
            )


def test_the_collision_parts_come_from_the_description(robot: MobileManipulator) -> None:
    """The base disc, the elbow, the wrist and the gripper, the forearm and the hand."""
    assert robot.collision.names == ("base", "elbow", "wrist", "gripper", "forearm", "hand")
    base = robot.collision.points[0]
    assert (base.frame, base.radius) == (0, robot.base.body_radius)
    forearm, hand = robot.collision.segments
    assert (forearm.frame, forearm.axis, forearm.start, forearm.end) == (3, "z", 1, 2)
    assert (hand.frame, hand.axis, hand.start, hand.end) == (5, "x", 2, 3)
    assert robot.with_velocity_max(np.ones(8)).collision == robot.collision


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (lambda c: c["points"][1].update(frame=9), "collision.points[1].frame: expected a frame"),
        (lambda c: c["points"][1].update(radius=0.0), "collision.points[1].radius"),
        (lambda c: c["points"][1].update(offset=[0, 0]), "collision.points[1].offset"),
        (lambda c: c["points"][1].update(colour="red"), "collision.points[1]: unknown fields"),
        (lambda c: c["points"][2].update(name="elbow"), "collision.points: names must differ"),
        (lambda c: c["segments"][0].update(axis="w"), "collision.segments[0].axis"),
        (lambda c: c["segments"][0].update(end="knee"), "collision.segments[0].end"),
        (
            lambda c: c["segments"][0].update(axis="x"),
            "collision.segments[0] (forearm): point wrist is 0.122 m off the x axis of frame 3",
        ),
        (lambda c: c["segments"][1].update(frame=4), "collision.segments[1] (hand): point"),
    ],
)
def test_a_broken_collision_section_names_the_field(
    tmp_path: Path, description: dict, change, expected: str
) -> None:
    broken = yaml.safe_load(yaml.safe_dump(description))
    change(broken["collision"])
    path = tmp_path / "broken_collision.yaml"
    path.write_text(yaml.safe_dump(broken))
    with pytest.raises(RobotDescriptionError) as raised:
        MobileManipulator.from_yaml(path)
    assert str(path) in str(raised.value) and expected in str(raised.value), str(raised.value)


# --- Geometry of the joint limits -------------------------------------------------------------

CLEARANCE = 0.03
SEGMENT_SAMPLES = np.linspace(0.0, 1.0, 41)[:, None]


def _points_too_close_to_the_base(robot: MobileManipulator, q: np.ndarray) -> bool:
    """True when a point of the arm from the elbow on lies within 3 cm of the base's top disc.

    The base sits at the origin facing x, so world and base frames coincide. The disc is the
    top of a cylinder of radius body_radius whose top is at base_height; a point clears it when
    it is above base_height + 3 cm or outside body_radius + 3 cm.
    """
    points = robot.link_points(q)[2:]
    segments = (
        points[:-1, None, :] * (1.0 - SEGMENT_SAMPLES) + points[1:, None, :] * SEGMENT_SAMPLES
    )
    samples = segments.reshape(-1, 3)
    low = samples[:, 2] < robot.base_height + CLEARANCE
    inside = np.hypot(samples[:, 0], samples[:, 1]) < robot.base.body_radius + CLEARANCE
    return bool(np.any(low & inside))


def test_joint_limits_keep_the_arm_off_the_base_top(robot: MobileManipulator) -> None:
    """Over a grid of the arm's joint box (end points included), no link comes near the base."""
    low, high = robot.q_min[3:], robot.q_max[3:]
    counts = (3, 7, 7, 9, 7)  # q1 only turns the arm about the base axis: three values suffice
    grids = [np.linspace(lo, hi, n) for lo, hi, n in zip(low, high, counts, strict=True)]
    colliding = [
        arm
        for arm in itertools.product(*grids)
        if _points_too_close_to_the_base(robot, np.concatenate(([0.0, 0.0, 0.0], arm)))
    ]
    if colliding:
        pytest.fail(
            f"{len(colliding)} of {np.prod(counts)} grid configurations bring the arm within "
            f"{CLEARANCE} m of the base top, e.g. q_arm = {np.round(colliding[0], 3).tolist()}"
        )


def test_clearance_check_detects_an_arm_folded_onto_the_base(robot: MobileManipulator) -> None:
    """The check itself can fail: forearm folded down, gripper pointing down at the base."""
    folded = np.array([0.0, 0.0, 0.0, 0.0, -0.7, 1.6, -1.9, 0.85])
    assert _points_too_close_to_the_base(robot, folded)
    assert not _points_too_close_to_the_base(robot, np.zeros(8))


def test_each_link_in_the_one_before_composes_into_the_frames(robot: MobileManipulator) -> None:
    """The planar base on the floor, then the base top and the DH links (4.1, 4.2, 4.4), each
    in the frame before it, multiply into ``frames(q)``; each link's outline starts at the
    origin of the frame before it, whatever the joint's angle."""
    rng = np.random.default_rng(7)
    for _ in range(20):
        q = rng.uniform(robot.q_min.clip(-3.0), robot.q_max.clip(max=3.0))
        pose = dq.pose(dq.rotation_quaternion(q[2], [0.0, 0.0, 1.0]), [q[0], q[1], 0.0])
        frames = robot.frames(q)
        for link, expected in zip(robot.link_transforms(q), frames, strict=True):
            pose = dq.mul(pose, link)
            assert np.allclose(pose, expected, atol=ORACLE_TOL)
        for i in range(1, robot.arm_dof + 1):
            rotation = dq.rotation_matrix(dq.rotation(frames[i]))
            start = rotation @ robot.link_outline(i)[0] + dq.translation(frames[i])[1:]
            assert np.allclose(start, dq.translation(frames[i - 1])[1:], atol=ORACLE_TOL)


def test_other_velocity_bounds_keep_the_description(robot: MobileManipulator) -> None:
    """Section 6.3's unbounded robot is the same chain, joints and base kind."""
    free = robot.with_velocity_max(np.full(robot.dof, 9.0))
    assert (free.joint_names, free.joint_types) == (robot.joint_names, robot.joint_types)
    assert free.base.kind == robot.base.kind == "differential" and free.chain is robot.chain
    np.testing.assert_array_equal(free.velocity_max, 9.0)
    q = random_configurations(robot, 1, seed=13)[0]
    np.testing.assert_array_equal(free.kinematics(q)[1], robot.kinematics(q)[1])


def test_the_joint_box_shrinks_a_range_about_zero_or_else_about_its_centre() -> None:
    """b_l [q-, q+] (5.14) for Little John, whose every range holds zero; a range that does not
    hold zero (the Panda's q4, -3.07 to -0.07 rad) shrinks about its centre, inside its limits
    (about zero, its upper end -0.063 would lie beyond -0.070)."""
    little_john = MobileManipulator.from_yaml(ROBOT_FILE)
    low, high = little_john.joint_box(0.9)
    np.testing.assert_array_equal(low, 0.9 * little_john.q_min)
    np.testing.assert_array_equal(high, 0.9 * little_john.q_max)
    panda = MobileManipulator.from_yaml(ROBOT_FILE.parent / "arm7_differential.yaml")
    low, high = panda.joint_box(0.9)
    assert np.all(low[3:] >= panda.q_min[3:]) and np.all(high[3:] <= panda.q_max[3:])
    centre = 0.5 * (panda.q_min[6] + panda.q_max[6])
    np.testing.assert_allclose(high[6] - centre, 0.9 * (panda.q_max[6] - centre))
