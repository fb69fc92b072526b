"""Robot descriptions (wbc/robot_description.py): the zoo, the bases' kinds in the laws, and
each description refused before anything starts, naming its field."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from profiles.deploy_files import ROBOT_FILE, ROBOTS_DIR, zoo
from tests.wbc.wbc_scenarios import context, pose_task, position_task
from wbc.laws.cascade_law import CascadeLaw
from wbc.laws.constraints.nonholonomic import Nonholonomic
from wbc.laws.lp_law import LPLaw
from wbc.laws.pinv_law import PinvParams, PseudoinverseLaw
from wbc.laws.qp_law import QPLaw
from wbc.robot import BASE_KINDS, JOINT_TYPES, MobileManipulator, RobotDescriptionError
from wbc.robot_description import read_mapping
from wbc.serial_chain import from_dh

DT = 0.02


@pytest.fixture(scope="module")
def youbot() -> MobileManipulator:
    return MobileManipulator.from_yaml(ROBOTS_DIR / "youbot.yaml")


@pytest.fixture(scope="module")
def ur5e() -> MobileManipulator:
    return MobileManipulator.from_yaml(ROBOTS_DIR / "ur5e_fixed.yaml")


# --- The zoo ----------------------------------------------------------------------------------


def test_the_zoo_is_every_description_sorted() -> None:
    names = [path.stem for path in zoo()]
    assert names == sorted(names)
    assert {"little_john", "open_manipulator_x", "youbot", "ur5e_fixed"} <= set(names)
    assert ROBOT_FILE in zoo()


@pytest.mark.parametrize("path", zoo(), ids=lambda p: p.stem)
def test_each_robot_of_the_zoo_loads_and_names_its_source(path: Path) -> None:
    robot = MobileManipulator.from_yaml(path)
    assert robot.arm_dof == len(robot.joint_names) == len(robot.joint_types) >= 1
    assert len(set(robot.joint_names)) == robot.arm_dof
    assert set(robot.joint_types) <= set(JOINT_TYPES) and robot.base.kind in BASE_KINDS
    assert path.read_text().startswith("# "), "a description names its source at its top"


def test_the_zoo_kinds() -> None:
    kinds = {p.stem: MobileManipulator.from_yaml(p).base.kind for p in zoo()}
    assert kinds["little_john"] == kinds["open_manipulator_x"] == "differential"
    assert (kinds["youbot"], kinds["ur5e_fixed"]) == ("omnidirectional", "fixed")
    ur5e = MobileManipulator.from_yaml(ROBOTS_DIR / "ur5e_fixed.yaml")
    assert ur5e.joint_names[0] == "shoulder_pan" and ur5e.arm_dof == 6


def test_a_dh_table_names_its_joints_q1_to_qn_by_default() -> None:
    assert MobileManipulator.from_yaml(ROBOT_FILE).joint_names == ("q1", "q2", "q3", "q4", "q5")
    assert from_dh(np.zeros((5, 2))).names == ("q1", "q2")


# --- The bases' kinds in the laws -------------------------------------------------------------


def _goal_beside(robot: MobileManipulator, q: np.ndarray, dx: float, dy: float) -> np.ndarray:
    goal = q.copy()
    goal[:2] += (dx, dy)
    return goal


def _laws(robot: MobileManipulator) -> dict:
    return {
        "lp": LPLaw(robot),
        "qp": QPLaw(robot),
        "classic": PseudoinverseLaw(robot),
        "classic nonholonomic": PseudoinverseLaw(robot, PinvParams(nonholonomic=True)),
    }


def test_a_fixed_base_never_moves_under_any_law(ur5e: MobileManipulator) -> None:
    """u_b = 0 exactly under every law (the QP's too: an entry whose bounds meet is the bound,
    not DAQP's round-off beside it), while the arm moves towards a goal it can reach."""
    np.testing.assert_array_equal(ur5e.velocity_max[:3], 0.0)
    q = np.array([0.0, 0.0, 0.0, 0.3, -1.2, 1.0, -0.5, 0.8, 0.2])
    goal = q.copy()
    goal[3:] += [0.2, -0.15, 0.1, 0.1, -0.2, 0.3]
    for name, law in _laws(ur5e).items():
        for task in (pose_task(ur5e, goal), position_task(ur5e, goal)):
            u = law.step(q, task, DT).u
            np.testing.assert_array_equal(u[:3], 0.0, err_msg=name)
            assert np.any(np.abs(u[3:]) > 1e-3), name
    assert ur5e.with_velocity_max(np.full(9, 5.0)).velocity_max[:3].tolist() == [0.0] * 3


def test_an_omnidirectional_base_moves_sideways(youbot: MobileManipulator) -> None:
    """A goal 0.5 m to the base's left, facing x: the LP moves y' (a differential base
    cannot), and the nonholonomic row is not there."""
    q = np.array([0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.3, 0.0])
    task = position_task(youbot, _goal_beside(youbot, q, 0.0, 0.5))
    for name, law in _laws(youbot).items():
        u = law.step(q, task, DT).u
        assert u[1] > 0.05, (name, u)
    assert Nonholonomic().rows(context(youbot, q)).matrix.shape == (0, youbot.dof)


def test_a_differential_base_keeps_its_row(youbot: MobileManipulator) -> None:
    robot = MobileManipulator.from_yaml(ROBOT_FILE)
    q = np.zeros(robot.dof)
    assert Nonholonomic().rows(context(robot, q)).matrix.shape == (1, robot.dof)
    u = LPLaw(robot).step(q, position_task(robot, _goal_beside(robot, q, 0.0, 0.5)), DT).u
    assert abs(u[1]) < 1e-9


@pytest.mark.parametrize("name", ["youbot", "ur5e_fixed"])
def test_the_cascade_refuses_a_base_that_is_not_differential(name: str) -> None:
    robot = MobileManipulator.from_yaml(ROBOTS_DIR / f"{name}.yaml")
    with pytest.raises(ValueError, match=f"base.kind is {robot.base.kind}: use lp, qp or classic"):
        CascadeLaw(robot)


# --- Refused, naming the field ----------------------------------------------------------------


def _little_john() -> dict:
    return yaml.safe_load(ROBOT_FILE.read_text())


def _omni(data: dict) -> dict:
    for key in ("wheel_base", "wheel_diameter", "wheel_speed_max"):
        del data["base"][key]
    data["base"]["kind"] = "omnidirectional"
    return data


def _fixed(data: dict) -> dict:
    data = _omni(data)
    data["base"]["kind"] = "fixed"
    del data["base"]["velocity_max"]
    return data


def _set(path: str, value: object):
    def change(data: dict) -> dict:
        *parents, key = path.split(".")
        node = data
        for parent in parents:
            node = node[parent]
        node[key] = value
        return data

    return change


def _urdf_arm(data: dict) -> dict:
    data["arm"] = {
        "urdf": {
            "file": str(ROBOTS_DIR / "open_manipulator_x.urdf"),
            "base_link": "base_link",
            "tip_link": "end_effector_link",
        }
    }
    data.pop("collision")
    return data


REFUSED = {
    "unknown-kind": (
        _set("base.kind", "tracked"),
        "base.kind: expected one of differential, omnidirectional, fixed, got 'tracked'",
    ),
    "fixed-moving": (
        lambda d: _set("base.velocity_max", [0.1, 0.0, 0.0])(_fixed(d)),
        "base.velocity_max: a fixed base never moves",
    ),
    "omni-wheels": (
        lambda d: _set("base.wheel_base", 0.3)(_omni(d)),
        "base.wheel_base: only a differential base has it, not omnidirectional",
    ),
    "omni-no-bounds": (
        lambda d: (_omni(d), d["base"].pop("velocity_max"))[0],
        "base.velocity_max: missing",
    ),
    "negative-bound": (
        _set("base.velocity_max", [0.2, -0.2, 1.0]),
        "base.velocity_max: must be >= 0",
    ),
    "nan-height": (_set("base.height", float("nan")), "base.height: expected a finite number"),
    "zero-wheel-base": (_set("base.wheel_base", 0.0), "base.wheel_base: expected a number > 0"),
    "both-arms": (
        lambda d: _set("arm.urdf", {"file": "x.urdf"})(d),
        "arm: expected one of dh or urdf",
    ),
    "no-arm-kind": (lambda d: (d["arm"].pop("dh"), d)[1], "arm: expected one of dh or urdf"),
    "unknown-type": (
        _set("arm.dh.type", ["revolute", "spherical", "revolute", "revolute", "revolute"]),
        "arm.dh.type: expected a list of revolute or prismatic",
    ),
    "short-row": (_set("arm.dh.d", [0.1, 0.0, 0.0, 0.1]), "arm.dh.d: expected shape (5,)"),
    "inf-row": (
        _set("arm.dh.a", [0.0, float("inf"), 0.0, 0.0, 0.1]),
        "arm.dh.a: values must be finite",
    ),
    "few-names": (_set("arm.dh.names", ["a", "b"]), "arm.dh.names: expected 5 different names"),
    "same-names": (
        _set("arm.dh.names", ["a", "b", "c", "d", "a"]),
        "arm.dh.names: expected 5 different names",
    ),
    "zero-speed": (
        _set("arm.velocity_max", [0.8, 0.8, 0.0, 0.8, 0.8]),
        "arm.velocity_max: must be > 0",
    ),
    "crossed-limits": (
        _set("arm.joint_min", [2.6, -1.9, -1.9, -2.5, -1.0]),
        "arm.joint_min: must not exceed joint_max",
    ),
    "urdf-limits": (
        lambda d: _set("arm.joint_min", [-1.0] * 4)(_urdf_arm(d)),
        "arm.joint_min: a URDF arm's limits come from its URDF",
    ),
    "urdf-cap-above": (
        lambda d: _set("arm.velocity_max", [0.8, 0.8, 5.0, 0.8])(_urdf_arm(d)),
        "arm.velocity_max: a commanded cap, at most the URDF's velocity limits",
    ),
    "urdf-no-tip": (
        lambda d: (_urdf_arm(d), d["arm"]["urdf"].pop("tip_link"))[0],
        "arm.urdf.tip_link: missing",
    ),
}


@pytest.mark.parametrize("case", REFUSED)
def test_an_unusable_description_is_refused_naming_the_field(tmp_path: Path, case: str) -> None:
    change, said = REFUSED[case]
    path = tmp_path / "robot.yaml"
    path.write_text(yaml.safe_dump(change(_little_john())))
    with pytest.raises(RobotDescriptionError) as raised:
        MobileManipulator.from_yaml(path)
    message = str(raised.value)
    assert message.startswith(f"{path}: ") and said in message, message
    assert "\n" not in message


def test_the_kinds_a_description_may_give_load(tmp_path: Path) -> None:
    """Little John's arm on an omnidirectional and on a fixed base; a URDF arm capped."""
    for change, kind in ((_omni, "omnidirectional"), (_fixed, "fixed")):
        path = tmp_path / f"{kind}.yaml"
        path.write_text(yaml.safe_dump(change(_little_john())))
        robot = MobileManipulator.from_yaml(path)
        assert robot.base.kind == kind and robot.base.wheel_base is None
    path = tmp_path / "urdf.yaml"
    path.write_text(yaml.safe_dump(_urdf_arm(_little_john())))
    assert MobileManipulator.from_yaml(path).velocity_max[3:].tolist() == [4.8] * 4


@pytest.mark.parametrize("path", sorted(ROBOTS_DIR.glob("*.yaml")), ids=lambda path: path.name)
def test_a_description_is_read_as_pyyaml_reads_it(path: Path) -> None:
    """libyaml's parser, which reads descriptions (several times faster), builds what PyYAML's
    does."""
    assert read_mapping(path) == yaml.safe_load(path.read_text())
