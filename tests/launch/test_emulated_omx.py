"""The OpenManipulator-X's emulated profile (deploy/emulated_omx.yaml): its X-series servos on
Dynamixel protocol 2.0, emulated byte for byte, driven by the arm driver's protocol 2.0 path in
the whole loop. One short launch for every assertion. Real processes, real Zenoh on loopback."""

from __future__ import annotations

import time
from pathlib import Path

from launch import query
from messages import codec, topics
from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from profiles.profile_files import read_profile_data
from studies.launched import connect, launched, wait_alive
from tests.launch.emulated_profiles import emulated_profile
from wbc.robot import MobileManipulator

DEADLINE_S = 60.0


def test_the_omx_profile_is_emulated_yaml_on_protocol_2_with_its_robot() -> None:
    omx, emulated = (
        read_profile_data(DEPLOY / "emulated_omx.yaml"),
        read_profile_data(DEPLOY / "emulated.yaml"),
    )
    specs = {c["name"]: c for c in omx["components"]}
    assert specs["arm_driver"]["params"]["protocol"] == 2
    assert specs["simulator"]["params"]["servo_protocol"] == 2
    assert MobileManipulator.from_yaml(omx["robot"]).name == "open_manipulator_x"
    assert omx["robot"] != emulated["robot"]
    assert {c["name"] for c in omx["components"]} == {c["name"] for c in emulated["components"]}


def test_the_omx_arm_moves_through_its_emulated_x_series_servos(tmp_path: Path) -> None:
    """The controller drives the pose set-up; the arm's joints move in the world as the driver
    reads them back, with no fault of any servo's answers."""
    path = emulated_profile(tmp_path, "omxtest", base="emulated_omx.yaml")
    profile = load_profile(path)
    log_path = tmp_path / "launch.log"
    states: list = []
    with log_path.open("w") as log, launched(path, log) as launcher:
        with connect(profile, launcher) as session:
            wait_alive(session, profile, launcher)
            session.declare_subscriber(
                topics.ARM_JOINT_STATES.key(profile.namespace),
                lambda s: states.append(
                    codec.decode(s.payload.to_bytes(), topics.ARM_JOINT_STATES.type)
                ),
            )
            deadline = time.monotonic() + DEADLINE_S

            def moved() -> float:
                if len(states) < 2:
                    return 0.0
                first, last = states[0].positions, states[-1].positions
                return max(abs(a - b) for a, b in zip(first, last, strict=True))

            while moved() < 0.05:
                assert time.monotonic() < deadline and launcher.poll() is None, "never moved"
                time.sleep(0.1)
            statuses = query.statuses(session, profile.namespace)
    text = log_path.read_text()
    assert launcher.returncode == 0, text
    assert states[-1].names == ("joint1", "joint2", "joint3", "joint4")
    driver = statuses["arm_driver"]
    assert driver.state == "running", driver.state
    assert driver.counters["reads"] > 0 and driver.counters["sync_writes"] > 0
    assert not any(v for k, v in driver.counters.items() if k.startswith("servo_")), text
    assert statuses["simulator"].counters["servo_bad_checksums"] == 0
    assert "[launch] arm_driver stopped (0)" in text
