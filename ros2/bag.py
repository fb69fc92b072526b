"""A robot's recorded states as a ROS 2 bag (Jazzy): rosbags' writer, MCAP storage with
``ros2msg`` schemas and the bag's metadata.yaml, one message per state on each topic of
``ros2.state_messages`` (logged at the state's stamp). States the estimator had no fix for
(``valid`` false) are left out and counted."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from rosbags.rosbag2 import StoragePlugin, Writer

from messages.base import default_joint_names
from messages.state import RobotState
from ros2.state_messages import JOINT_STATES, ODOM, TF, joint_state, odometry, tf_message
from ros2.urdf import joints
from ros2.wire import typestore
from wbc.robot import MobileManipulator

BAG_VERSION = 9
"""rosbag2's metadata version of Jazzy's bags."""


def check_joints(state: RobotState, robot: MobileManipulator) -> None:
    """``ValueError`` unless the state's joints are the robot's: as many, and named as it names
    them (or unnamed, ``q1 .. qn``, as recordings made before messages named them)."""
    names = state.joint_names
    if len(names) != robot.arm_dof:
        raise ValueError(
            f"a state has {len(names)} arm joints, robot {robot.name} {robot.arm_dof}: "
            "give the recorded robot (--robot)"
        )
    if names not in (robot.joint_names, default_joint_names(len(names))):
        raise ValueError(
            f"a state's joints {list(names)} are not robot {robot.name}'s "
            f"{list(robot.joint_names)}: give the recorded robot (--robot)"
        )


def write_bag(directory: Path, robot: MobileManipulator, states: Iterable[RobotState]) -> dict:
    """Write the bag into ``directory`` (which must not exist); its summary: topics and their
    message counts, the time span (first and last stamp, ns), the states left out, the size
    in bytes. ``ValueError`` if a state's joints are not the robot's."""
    store, tree = typestore(), joints(robot)
    counts = dict.fromkeys((JOINT_STATES[0], TF[0], ODOM[0]), 0)
    span, invalid, before = [None, None], 0, None
    writer = Writer(directory, version=BAG_VERSION, storage_plugin=StoragePlugin.MCAP)
    with writer:
        connections = {
            topic: writer.add_connection(topic, msgtype, typestore=store)
            for topic, msgtype in (JOINT_STATES, TF, ODOM)
        }
        for state in states:
            check_joints(state, robot)
            if not state.valid:
                invalid += 1
                continue
            stamp = state.header.stamp_ns
            made = {
                JOINT_STATES: joint_state(state, robot.joint_names),
                TF: tf_message(state, tree),
                ODOM: odometry(state, before),
            }
            for (topic, msgtype), message in made.items():
                data = store.serialize_cdr(message, msgtype)
                writer.write(connections[topic], stamp, data)
                counts[topic] += 1
            span = [stamp if span[0] is None else span[0], stamp]
            before = state
    size = sum(p.stat().st_size for p in directory.iterdir() if p.is_file())
    return {
        "bag": str(directory),
        "storage": "mcap",
        "topics": counts,
        "start_ns": span[0],
        "end_ns": span[1],
        "duration_s": (span[1] - span[0]) * 1e-9 if span[0] is not None else 0.0,
        "invalid_states_left_out": invalid,
        "size_bytes": size,
    }
