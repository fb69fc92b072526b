"""A recorded session as a ROS 2 bag (Jazzy): rosbags' writer, MCAP storage with ``ros2msg``
schemas and the bag's metadata.yaml, the topics the live bridge (``components.ros2_bridge``)
publishes, made by the same builders: per robot state, /joint_states, /tf and /odom
(``ros2.state_messages``, logged at the state's stamp); /robot_description (the URDF, once, at
the first state's stamp, offered TRANSIENT_LOCAL as a latched topic is); per JPEG camera frame,
/camera/image/compressed and /camera/camera_info; per controller diagnostics or supervisor
status, /diagnostics with the newest of both (``ros2.bridge_messages``). States the estimator
had no fix for (``valid`` false) and camera frames not JPEG are left out and counted."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from pydantic import BaseModel
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import StoragePlugin, Writer

from messages.base import default_joint_names
from messages.camera import CameraFrame
from messages.diagnostics import ControllerDiagnostics
from messages.state import RobotState
from messages.supervisor import SupervisorStatus
from ros2 import bridge_messages as made
from ros2.state_messages import JOINT_STATES, ODOM, TF, joint_state, odometry, tf_message
from ros2.urdf import joints, urdf
from ros2.wire import typestore
from wbc.robot import MobileManipulator

BAG_VERSION = 9
"""rosbag2's metadata version of Jazzy's bags."""
INFINITE = QosTime(sec=9223372036, nsec=854775807)
"""RMW_DURATION_INFINITE, as rosbag2 writes an unset deadline, lifespan or lease."""
LATCHED_QOS = Qos(
    history=QosHistory.KEEP_LAST,
    depth=1,
    reliability=QosReliability.RELIABLE,
    durability=QosDurability.TRANSIENT_LOCAL,
    deadline=INFINITE,
    lifespan=INFINITE,
    liveliness=QosLiveliness.AUTOMATIC,
    liveliness_lease_duration=INFINITE,
    avoid_ros_namespace_conventions=False,
)
"""The offered QoS of /robot_description: `ros2 bag play` offers it again, so a late joiner
(rviz2's RobotModel) gets the URDF, as from the bridge."""


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


class _Bag:
    """The open writer, a connection per topic (added with its first message), the counts
    and the time span of what was written."""

    def __init__(self, writer: Writer) -> None:
        self.writer, self.store = writer, typestore()
        self.connections: dict[str, object] = {}
        self.counts: dict[str, int] = {}
        self.span: list[int | None] = [None, None]

    def add(self, topic: tuple[str, str], qos: tuple[Qos, ...] = ()) -> None:
        name, msgtype = topic
        self.connections[name] = self.writer.add_connection(
            name, msgtype, typestore=self.store, offered_qos_profiles=qos
        )
        self.counts[name] = 0

    def write(self, topic: tuple[str, str], stamp: int, message) -> None:
        if topic[0] not in self.connections:
            self.add(topic)
        data = self.store.serialize_cdr(message, topic[1])
        self.writer.write(self.connections[topic[0]], stamp, data)
        self.counts[topic[0]] += 1
        first, last = self.span
        self.span = [stamp if first is None else min(first, stamp), max(last or stamp, stamp)]


def write_bag(directory: Path, robot: MobileManipulator, messages: Iterable[BaseModel]) -> dict:
    """Write the bag of ``messages`` (robot states, camera frames, controller diagnostics,
    supervisor statuses, in log-time order; others are passed over) into ``directory`` (which
    must not exist); its summary: topics and their message counts, the time span (first and
    last stamp, ns), the states and frames left out, the size in bytes. ``ValueError`` if a
    state's joints are not the robot's."""
    tree = joints(robot)
    before: RobotState | None = None
    invalid, not_jpeg = 0, 0
    newest: dict[type, object] = {}  # the newest controller and supervisor statuses
    with Writer(directory, version=BAG_VERSION, storage_plugin=StoragePlugin.MCAP) as writer:
        bag = _Bag(writer)
        for topic in (JOINT_STATES, TF, ODOM):
            bag.add(topic)
        bag.add(made.ROBOT_DESCRIPTION, (LATCHED_QOS,))
        for message in messages:
            stamp = getattr(getattr(message, "header", None), "stamp_ns", 0)
            if isinstance(message, RobotState):
                check_joints(message, robot)
                if not message.valid:
                    invalid += 1
                    continue
                if before is None:
                    bag.write(made.ROBOT_DESCRIPTION, stamp, made.string(urdf(robot)))
                bag.write(JOINT_STATES, stamp, joint_state(message, robot.joint_names))
                bag.write(TF, stamp, tf_message(message, tree))
                bag.write(ODOM, stamp, odometry(message, before))
                before = message
            elif isinstance(message, CameraFrame):
                if message.encoding != "jpeg":
                    not_jpeg += 1
                    continue
                bag.write(
                    made.COMPRESSED_IMAGE, stamp, made.compressed_image(message, message.data)
                )
                bag.write(made.CAMERA_INFO, stamp, made.camera_info(message))
            elif isinstance(message, ControllerDiagnostics | SupervisorStatus):
                newest[type(message)] = message
                statuses = []
                if (controller := newest.get(ControllerDiagnostics)) is not None:
                    statuses.append(made.controller_status(controller))
                if (supervisor := newest.get(SupervisorStatus)) is not None:
                    statuses.append(made.supervisor_status(supervisor))
                bag.write(made.DIAGNOSTICS, stamp, made.diagnostic_array(stamp, statuses))
    first, last = bag.span
    size = sum(p.stat().st_size for p in directory.iterdir() if p.is_file())
    return {
        "bag": str(directory),
        "storage": "mcap",
        "topics": bag.counts,
        "start_ns": first,
        "end_ns": last,
        "duration_s": (last - first) * 1e-9 if first is not None else 0.0,
        "invalid_states_left_out": invalid,
        "frames_not_jpeg_left_out": not_jpeg,
        "size_bytes": size,
    }
