"""analysis.commands on sessions of real kinematic runs of the LP (tests/analysis/conftest.py's):
the commands as control inputs, and their CSV."""

from __future__ import annotations

import yaml

from analysis.commands import commands_csv
from profiles.deploy_files import ROBOT_FILE
from tests.analysis.conftest import ROBOT
from wbc.robot import MobileManipulator


def test_the_commands_csv_has_a_column_per_joint_of_the_robots_arm(runs, tmp_path):
    _, session = runs["LP"]
    lines = commands_csv(session, ROBOT).splitlines()
    joints = [f"q{i}_dot" for i in range(1, ROBOT.arm_dof + 1)]
    assert lines[0].split(",") == ["stamp_s", "forward", "angular", *joints]
    assert {len(line.split(",")) for line in lines[1:]} == {len(lines[0].split(","))}
    description = yaml.safe_load(ROBOT_FILE.read_text())
    arm = description["arm"]
    arm["dh"] = {key: values[:4] for key, values in arm["dh"].items()}
    for key in ("joint_min", "joint_max", "velocity_max"):
        arm[key] = arm[key][:4]
    del description["collision"]
    (tmp_path / "four_joints.yaml").write_text(yaml.safe_dump(description))
    four = MobileManipulator.from_yaml(tmp_path / "four_joints.yaml")
    header = commands_csv(session, four).splitlines()[0].split(",")
    assert header[3:] == ["q1_dot", "q2_dot", "q3_dot", "q4_dot"]
