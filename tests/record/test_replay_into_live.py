"""A replay cannot drive a live system by accident: commands and topics that a live component
publishes are refused before anything is sent, unless the user says --into-live."""

from __future__ import annotations

import subprocess
from pathlib import Path

import yaml

from launch.query import live_components
from messages import topics
from messages.clock import Clock
from messages.commands import ArmCommand
from messages.header import Header
from messages.state import RobotState
from profiles.endpoints import free_port
from profiles.profile import load_profile
from record.session_file import SessionWriter
from studies.launched import connect, launched
from tests.parsimony.in_process import completed


def recording(path: Path, namespace: str) -> Path:
    """A second of a recorded arm command, state and clock at 50 Hz."""
    with SessionWriter(path) as writer:
        for index in range(50):
            stamp = index * 20_000_000
            header = Header(stamp_ns=stamp, frame="world", seq=index, source="recorded")
            writer.write(
                topics.ARM_COMMAND.key(namespace),
                ArmCommand(header=header, joint_velocities=(0.1,) * 5),
            )
            writer.write(
                topics.ROBOT_STATE.key(namespace),
                RobotState(
                    header=header,
                    base_pose=(0.0, 0.0, 0.0),
                    arm_joints=(0.0,) * 5,
                    end_effector=(1.0, 0, 0, 0, 0, 0, 0, 0),
                    valid=True,
                    age_s=0.0,
                ),
            )
            writer.write(topics.SIM_CLOCK.key(namespace), Clock(stamp_ns=stamp))
    return path


def replay(file: Path, profile: Path, *extra: str) -> subprocess.CompletedProcess:
    return completed("replay", str(file), "--profile", str(profile), "--rate", "16", *extra)


def test_a_replay_into_a_live_namespace_refuses_commands_and_live_topics(tmp_path: Path) -> None:
    profile = tmp_path / "live.yaml"
    profile.write_text(
        yaml.safe_dump(
            {
                "namespace": "live",
                "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
                "components": [{"name": "pub", "module": "scripted_publisher", "role": "tool"}],
            }
        )
    )
    file = recording(tmp_path / "k.mcap", "live")
    with launched(profile) as launcher, connect(load_profile(profile), launcher) as session:
        while "pub" not in live_components(session, "live", 0.5):
            assert launcher.poll() is None
        sent: list = []
        key = topics.ARM_COMMAND.key("live")
        session.declare_subscriber(key, lambda sample: sent.append(sample))
        refused = replay(file, profile)
        assert refused.returncode == 2, refused.stderr
        assert "arm/command into live, where pub are alive" in refused.stderr
        assert "robot/state, which the live pub publishes" in refused.stderr
        assert "sim/clock" not in refused.stderr and "Traceback" not in refused.stderr
        # Leaving out what clashes, the clock alone goes in.
        clock_only = replay(file, profile, "--exclude", "arm/command", "robot/state")
        assert clock_only.returncode == 0, clock_only.stderr
        # Into a namespace of its own everything goes; --into-live says the user means it.
        assert replay(file, profile, "--namespace", "mine").returncode == 0
        assert not sent, "nothing reached the live namespace's commands"
        meant = replay(file, profile, "--into-live")
        assert meant.returncode == 0, meant.stderr
