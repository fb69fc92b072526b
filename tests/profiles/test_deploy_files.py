"""profiles.deploy_files: the deploy folder holds every profile a user names, the robot
description and the lab's files, as data only (no Python), and each profile there loads."""

from __future__ import annotations

from profiles.deploy_files import DEPLOY, ROBOT_FILE
from profiles.profile import load_profile
from wbc.robot import MobileManipulator


def test_every_profile_in_the_deploy_folder_loads() -> None:
    names = {path.name for path in DEPLOY.glob("*.yaml")}
    assert {"sim.yaml", "hardware.yaml", "emulated.yaml", "sim_station.yaml"} <= names
    for name in names:
        assert load_profile(DEPLOY / name).namespace


def test_the_robot_description_and_the_lab_are_there_and_no_code() -> None:
    assert MobileManipulator.from_yaml(ROBOT_FILE).arm_dof > 0
    assert list((DEPLOY / "lab").glob("*.yaml"))
    assert not list(DEPLOY.rglob("*.py"))
