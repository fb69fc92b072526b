"""A robot whose arm a URDF gives (wbc/urdf_chain.py): its poses and Jacobians against
Pinocchio, an independent library, and each URDF it must refuse."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from profiles.deploy_files import ROBOTS_DIR
from tests.wbc.wbc_scenarios import central_difference
from wbc import dq
from wbc.robot import MobileManipulator, RobotDescriptionError

PINOCCHIO_TOL = 1e-9
OPEN_MANIPULATOR = ROBOTS_DIR / "open_manipulator_x.yaml"


def _random_urdf(seed: int) -> str:
    """A chain of six revolute and prismatic joints about and along tilted axes, with tilted
    origins and a fixed joint between two of them and after the last (and a finger off it)."""
    rng = np.random.default_rng(seed)
    joints, parent = [], "base_link"
    kinds = ["revolute", "prismatic", "revolute", "fixed", "revolute", "prismatic", "revolute"]
    for i, kind in enumerate([*kinds, "fixed"]):
        xyz = " ".join(f"{v:.6f}" for v in rng.uniform(-0.2, 0.2, 3))
        rpy = " ".join(f"{v:.6f}" for v in rng.uniform(-np.pi, np.pi, 3))
        axis = " ".join(f"{v:.6f}" for v in rng.normal(size=3))
        lower, upper = (-2.5, 2.5) if kind == "revolute" else (-0.3, 0.4)
        limit = f'<limit lower="{lower}" upper="{upper}" velocity="1.5" effort="1"/>'
        extra = "" if kind == "fixed" else f'<axis xyz="{axis}"/>{limit}'
        joints.append(
            f'<joint name="j{i}" type="{kind}"><parent link="{parent}"/><child link="l{i}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/>{extra}</joint><link name="l{i}"/>'
        )
        parent = f"l{i}"
    finger = (
        '<joint name="finger" type="prismatic"><parent link="l4"/><child link="finger_link"/>'
        '<axis xyz="0 1 0"/><limit lower="0" upper="0.02" velocity="1" effort="1"/></joint>'
        '<link name="finger_link"/>'
    )
    return f'<robot name="random"><link name="base_link"/>{"".join(joints)}{finger}</robot>'


BASE = """
base: {kind: omnidirectional, height: 0.3, body_radius: 0.2, velocity_max: [0.2, 0.2, 1.0]}
"""


def _write_robot(tmp_path: Path, urdf: str, tip: str = "l7", base: str = "base_link") -> Path:
    (tmp_path / "arm.urdf").write_text(urdf)
    path = tmp_path / "robot.yaml"
    path.write_text(f"arm:\n  urdf: {{file: arm.urdf, base_link: {base}, tip_link: {tip}}}\n{BASE}")
    return path


def _pinocchio_q(model, robot: MobileManipulator, q: np.ndarray) -> np.ndarray:
    config = pin.neutral(model)
    config[:4] = [q[0], q[1], np.cos(q[2]), np.sin(q[2])]
    for name, value in zip(robot.joint_names, q[3:], strict=True):
        config[model.joints[model.getJointId(name)].idx_q] = value
    return config


def _velocity_map(model, robot: MobileManipulator, phi: float) -> np.ndarray:
    """(nv, dof): our u = [x', y', phi', arm] to Pinocchio's velocity (the planar joint's in
    its own frame)."""
    mapping = np.zeros((model.nv, robot.dof))
    c, s = np.cos(phi), np.sin(phi)
    mapping[:3, :3] = [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]
    for i, name in enumerate(robot.joint_names):
        mapping[model.joints[model.getJointId(name)].idx_v, 3 + i] = 1.0
    return mapping


def _check_against_pinocchio(robot: MobileManipulator, urdf: Path, tip: str, seed: int) -> float:
    """The largest difference, over random configurations, between our poses and pose
    Jacobians of every frame and Pinocchio's."""
    model = pin.buildModelFromUrdf(str(urdf), pin.JointModelPlanar())
    data = model.createData()
    links = ["base_link", *(model.frames[f].name for f in _child_frames(model, robot)), tip]
    ids = [model.getFrameId(name) for name in links]
    rng = np.random.default_rng(seed)
    worst = 0.0
    for _ in range(50):
        low, high = np.maximum(robot.q_min, -3.0), np.minimum(robot.q_max, 3.0)
        q = rng.uniform(low, high)
        config = _pinocchio_q(model, robot, q)
        pin.computeJointJacobians(model, data, config)
        pin.updateFramePlacements(model, data)
        mapping = _velocity_map(model, robot, q[2])
        poses, jacobians = robot.frame_kinematics(q)
        for i, frame in enumerate(ids):
            placement = data.oMf[frame]
            translation = placement.translation + [0.0, 0.0, robot.base_height]
            ours = poses[i]
            worst = max(
                worst,
                np.abs(dq.translation(ours)[1:] - translation).max(),
                np.abs(dq.rotation_matrix(ours[:4]) - placement.rotation).max(),
            )
            spatial = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED) @ mapping
            velocity, omega = spatial[:3], spatial[3:]
            # x' = (1/2) xi x, xi = omega + eps (p' + p x omega): Pinocchio's as a pose Jacobian.
            dual = velocity + np.cross(translation, omega.T).T
            xi = np.vstack((np.zeros(robot.dof), omega, np.zeros(robot.dof), dual))
            expected = 0.5 * dq.haminus8(ours) @ xi
            worst = max(worst, np.abs(jacobians[i] - expected).max())
    return worst


def _child_frames(model, robot: MobileManipulator) -> list[int]:
    """The frames of the child links of our joints but the last (whose frame is the tip)."""
    found = []
    for name in robot.joint_names[:-1]:
        joint = model.getJointId(name)
        bodies = (
            i
            for i, frame in enumerate(model.frames)
            if frame.parentJoint == joint and frame.type == pin.FrameType.BODY
        )
        found.append(next(bodies))
    return found


def _random_robot(tmp_path: Path, seed: int) -> tuple[MobileManipulator, Path]:
    path = _write_robot(tmp_path, _random_urdf(seed))
    return MobileManipulator.from_yaml(path), tmp_path / "arm.urdf"


# --- Against Pinocchio ------------------------------------------------------------------------


def test_open_manipulator_matches_pinocchio() -> None:
    """Every frame's pose and pose Jacobian, base included, on random configurations."""
    robot = MobileManipulator.from_yaml(OPEN_MANIPULATOR)
    urdf = ROBOTS_DIR / "open_manipulator_x.urdf"
    worst = _check_against_pinocchio(robot, urdf, "end_effector_link", seed=1)
    assert worst < PINOCCHIO_TOL, worst


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_tilted_chain_of_revolute_and_prismatic_joints_matches_pinocchio(
    tmp_path: Path, seed: int
) -> None:
    robot, urdf = _random_robot(tmp_path, seed)
    assert robot.joint_types == (
        "revolute",
        "prismatic",
        "revolute",
        "revolute",
        "prismatic",
        "revolute",
    )
    assert robot.joint_names == ("j0", "j1", "j2", "j4", "j5", "j6")
    worst = _check_against_pinocchio(robot, urdf, "l7", seed=seed)
    assert worst < PINOCCHIO_TOL, worst


def test_the_bounds_come_from_the_urdf(tmp_path: Path) -> None:
    robot, _ = _random_robot(tmp_path, 1)
    np.testing.assert_array_equal(robot.q_min[3:], [-2.5, -0.3, -2.5, -2.5, -0.3, -2.5])
    np.testing.assert_array_equal(robot.q_max[3:], [2.5, 0.4, 2.5, 2.5, 0.4, 2.5])
    np.testing.assert_array_equal(robot.velocity_max[3:], [1.5] * 6)
    open_manipulator = MobileManipulator.from_yaml(OPEN_MANIPULATOR)
    np.testing.assert_array_equal(open_manipulator.q_min[3:], [-np.pi, -1.5, -1.5, -1.7])
    np.testing.assert_array_equal(open_manipulator.velocity_max[3:], [0.8] * 4)


def test_a_prismatic_joint_jacobian_is_the_derivative_of_the_pose(tmp_path: Path) -> None:
    robot, _ = _random_robot(tmp_path, 2)
    rng = np.random.default_rng(5)
    for _ in range(10):
        q = rng.uniform(np.maximum(robot.q_min, -2.0), np.minimum(robot.q_max, 2.0))
        jacobian = robot.pose_jacobian(q)
        np.testing.assert_allclose(jacobian, central_difference(robot.fkm, q), rtol=0, atol=1e-7)


def test_a_link_outline_is_fixed_in_both_its_frames(tmp_path: Path) -> None:
    """A revolute link's outline starts on its joint's axis: turning the joint moves that point
    neither in frame i (where the outline is drawn) nor in frame i-1."""
    robot, _ = _random_robot(tmp_path, 3)
    q = np.zeros(robot.dof)
    for i, kind in enumerate(robot.joint_types, start=1):
        if kind != "revolute":
            continue
        seen = []
        for angle in (-1.0, 0.0, 1.3):
            q[2 + i] = angle
            frames = robot.frames(q)
            start = dq.mul(frames[i], dq.pose(dq.ONE[:4], robot.link_outline(i)[0]))
            seen.append(dq.translation(dq.mul(dq.conj(frames[i - 1]), start))[1:])
        np.testing.assert_allclose(seen, [seen[0]] * 3, rtol=0, atol=1e-12)


# --- Refused, naming the field ----------------------------------------------------------------

LIMIT = '<limit lower="-1" upper="1" velocity="1" effort="1"/>'


def _two_joints(first: str = f'type="revolute">{LIMIT}', second: str = "") -> str:
    """base_link -> a (joint ja) -> b (joint jb); ``second`` adds to the file."""
    return (
        '<robot name="r"><link name="base_link"/><link name="a"/><link name="b"/>'
        f'<joint name="ja" {first}<parent link="base_link"/><child link="a"/></joint>'
        f'<joint name="jb" type="revolute"><parent link="a"/><child link="b"/>{LIMIT}</joint>'
        f"{second}</robot>"
    )


SIDE_BRANCH = (
    '<link name="c"/><joint name="jc" type="revolute"><parent link="base_link"/>'
    f'<child link="c"/>{LIMIT}</joint>'
)


@pytest.mark.parametrize(
    ("urdf", "tip", "base", "said"),
    [
        (_two_joints('type="continuous">'), "b", "base_link", "joint 'ja': type continuous"),
        (_two_joints('type="floating">'), "b", "base_link", "joint 'ja': type floating"),
        (_two_joints('type="revolute">'), "b", "base_link", "joint 'ja': needs a <limit>"),
        (
            _two_joints('type="revolute"><limit lower="-1" upper="1" effort="1"/>'),
            "b",
            "base_link",
            "joint 'ja': <limit> needs velocity",
        ),
        (
            _two_joints('type="revolute"><limit upper="1" velocity="1" effort="1"/>'),
            "b",
            "base_link",
            "joint 'ja': <limit> needs lower",
        ),
        (
            _two_joints('type="revolute"><limit lower="-1" upper="inf" velocity="1" effort="1"/>'),
            "b",
            "base_link",
            "joint 'ja': <limit> upper must be finite",
        ),
        (
            _two_joints('type="revolute"><limit lower="1" upper="-1" velocity="1" effort="1"/>'),
            "b",
            "base_link",
            "joint 'ja': <limit> lower 1.0 exceeds upper -1.0",
        ),
        (
            _two_joints(f'type="revolute"><origin xyz="0 nan 0"/>{LIMIT}'),
            "b",
            "base_link",
            "joint 'ja': <origin> must be finite numbers",
        ),
        (
            _two_joints(f'type="revolute"><axis xyz="0 0 0"/>{LIMIT}'),
            "b",
            "base_link",
            "joint 'ja': <axis> must be a nonzero finite 3-vector",
        ),
        (
            _two_joints(f'type="revolute"><mimic joint="jb"/>{LIMIT}'),
            "b",
            "base_link",
            "joint 'ja': <mimic> joints are not supported",
        ),
        (_two_joints(), "hand", "base_link", "arm.urdf.tip_link: no link 'hand' in arm.urdf"),
        (_two_joints(), "b", "world", "arm.urdf.base_link: no link 'world' in arm.urdf"),
        (
            _two_joints(second=SIDE_BRANCH),
            "c",
            "a",
            "arm.urdf.tip_link: 'c' is not below base_link 'a'",
        ),
        (_two_joints(), "base_link", "base_link", "no revolute or prismatic joint"),
        ("not XML", "b", "base_link", "arm.urdf.file: "),
    ],
    ids=[
        "continuous",
        "floating",
        "no-limit",
        "no-velocity",
        "no-lower",
        "infinite-limit",
        "lower-above-upper",
        "nan-origin",
        "zero-axis",
        "mimic",
        "no-tip",
        "no-base",
        "branching",
        "no-joint",
        "not-xml",
    ],
)
def test_an_unusable_urdf_is_refused_naming_the_field(
    tmp_path: Path, urdf: str, tip: str, base: str, said: str
) -> None:
    path = _write_robot(tmp_path, urdf, tip=tip, base=base)
    with pytest.raises(RobotDescriptionError) as raised:
        MobileManipulator.from_yaml(path)
    message = str(raised.value)
    assert message.startswith(f"{path}: ") and said in message, message
    assert "\n" not in message


def test_a_missing_urdf_file_is_named(tmp_path: Path) -> None:
    path = tmp_path / "robot.yaml"
    path.write_text(f"arm:\n  urdf: {{file: gone.urdf, base_link: a, tip_link: b}}\n{BASE}")
    with pytest.raises(RobotDescriptionError, match=r"arm.urdf.file: no file .*gone.urdf"):
        MobileManipulator.from_yaml(path)


def test_a_gripper_branching_off_the_chain_is_left_out() -> None:
    """The Open Manipulator-X's fingers branch off link5, beside the chain to the tip."""
    robot = MobileManipulator.from_yaml(OPEN_MANIPULATOR)
    assert robot.joint_names == ("joint1", "joint2", "joint3", "joint4")
    assert robot.arm_dof == 4 and robot.base.kind == "differential"
