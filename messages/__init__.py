"""Every message that crosses a process boundary, the topic table, and the codec.

Typical use in a component::

    session.put(ROBOT_STATE.key(namespace), encode(state))
    state = decode(sample.payload.to_bytes(), RobotState, str(sample.key_expr))
"""

from messages.base import IDENTITY_POSE, Message
from messages.camera import CHANNELS, CameraFrame, CameraIntrinsics
from messages.clock import Clock
from messages.codec import FORMAT_TAG, FORMAT_VERSION, DecodeError, decode, encode
from messages.commands import ArmCommand, BaseCommand
from messages.diagnostics import ControllerDiagnostics
from messages.goal import Goal
from messages.header import Header
from messages.joints import JointStates
from messages.markers import MarkerDetection, MarkerDetections
from messages.obstacles import Circle, Obstacles
from messages.odometry import BaseOdometry
from messages.state import RobotState
from messages.status import ComponentStatus
from messages.topics import (
    ARM_COMMAND,
    ARM_JOINT_STATES,
    BASE_COMMAND,
    BASE_ODOMETRY,
    CAMERA_IMAGE,
    CONTROL_DIAGNOSTICS,
    CONTROL_GOAL,
    MESSAGE_TYPES,
    ROBOT_STATE,
    SIM_CLOCK,
    STATUS_TYPE,
    TOPICS,
    VISION_MARKERS,
    WORLD_OBSTACLES,
    KeyExpressionError,
    Topic,
    check_component,
    check_namespace,
    component_of_liveliness_key,
    component_of_status_key,
    key,
    liveliness_key,
    liveliness_selector,
    namespace_selector,
    param_key,
    param_selector,
    status_key,
    status_selector,
    topic_of_key,
)

__all__ = [
    "ARM_COMMAND",
    "ARM_JOINT_STATES",
    "BASE_COMMAND",
    "BASE_ODOMETRY",
    "CAMERA_IMAGE",
    "CHANNELS",
    "CONTROL_DIAGNOSTICS",
    "CONTROL_GOAL",
    "FORMAT_TAG",
    "FORMAT_VERSION",
    "IDENTITY_POSE",
    "MESSAGE_TYPES",
    "ROBOT_STATE",
    "SIM_CLOCK",
    "STATUS_TYPE",
    "TOPICS",
    "VISION_MARKERS",
    "WORLD_OBSTACLES",
    "ArmCommand",
    "BaseCommand",
    "BaseOdometry",
    "CameraFrame",
    "CameraIntrinsics",
    "Circle",
    "Clock",
    "ComponentStatus",
    "ControllerDiagnostics",
    "DecodeError",
    "Goal",
    "Header",
    "JointStates",
    "KeyExpressionError",
    "MarkerDetection",
    "MarkerDetections",
    "Message",
    "Obstacles",
    "RobotState",
    "Topic",
    "check_component",
    "check_namespace",
    "component_of_liveliness_key",
    "component_of_status_key",
    "decode",
    "encode",
    "key",
    "liveliness_key",
    "liveliness_selector",
    "namespace_selector",
    "param_key",
    "param_selector",
    "status_key",
    "status_selector",
    "topic_of_key",
]
