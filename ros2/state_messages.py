"""The robot's state as ROS 2 Jazzy messages (rosbags' message classes): /joint_states
(sensor_msgs/JointState), /tf (tf2_msgs/TFMessage: world -> base_footprint, then every joint
of the URDF's tree, ``ros2.urdf.joints``) and /odom (nav_msgs/Odometry of base_footprint in
world, its twist in base_footprint from the state before)."""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from messages.state import RobotState
from ros2.urdf import ROOT, Joint, planar
from ros2.wire import typestore
from wbc import dq

Array = np.ndarray

WORLD = "world"
JOINT_STATES = ("/joint_states", "sensor_msgs/msg/JointState")
TF = ("/tf", "tf2_msgs/msg/TFMessage")
ODOM = ("/odom", "nav_msgs/msg/Odometry")
TOPICS = (JOINT_STATES, TF, ODOM)
"""(topic, ROS 2 type) of every topic made from a state."""


def _types():
    return typestore().types


def header(stamp_ns: int, frame: str):
    """std_msgs/Header at ``stamp_ns`` (ns since the epoch) in ``frame``."""
    types = _types()
    stamp = types["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    return types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)


@lru_cache(maxsize=1024)
def _unit_quaternion(rotation: bytes) -> tuple[float, ...]:
    """(w, x, y, z) of a rotation matrix's bytes (a fixed joint's come again with every state)."""
    return tuple(float(v) for v in dq.quaternion_of_matrix(np.frombuffer(rotation).reshape(3, 3)))


def _wxyz(rotation: Array) -> tuple[float, ...]:
    return _unit_quaternion(np.ascontiguousarray(rotation, dtype=np.float64).tobytes())


def _quaternion(rotation: Array, wxyz: tuple[float, ...] | None = None):
    w, x, y, z = _wxyz(rotation) if wxyz is None else wxyz
    return _types()["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w)


def _turn(joint: Joint, q_arm: Array) -> tuple[float, ...]:
    """(w, x, y, z) of a joint's rotation at ``q_arm``: its origin's (the same with every
    state), then its own turn about its axis, as quaternions (no matrix to convert)."""
    origin = _wxyz(joint.origin[:3, :3])
    if joint.index is None or joint.kind == "prismatic":
        return origin
    turn = dq.rotation_quaternion(float(q_arm[joint.index]), joint.axis)
    return tuple(float(v) for v in dq.qmul(np.array(origin), turn))


def _vector(kind: str, values) -> object:
    x, y, z = (float(v) for v in values)
    return _types()[f"geometry_msgs/msg/{kind}"](x=x, y=y, z=z)


def joint_state(state: RobotState, names: tuple[str, ...]):
    """sensor_msgs/JointState of the arm's joints, named as the URDF names them."""
    return _types()["sensor_msgs/msg/JointState"](
        header=header(state.header.stamp_ns, ""),
        name=list(names),
        position=np.array(state.arm_joints, dtype=np.float64),
        velocity=np.zeros(0),
        effort=np.zeros(0),
    )


def transform_stamped(
    stamp_ns: int, parent: str, child: str, pose: Array, wxyz: tuple[float, ...] | None = None
):
    """geometry_msgs/TransformStamped of ``child`` at ``pose`` (4x4) in ``parent``; ``wxyz``
    its rotation's quaternion when known (else taken from the matrix)."""
    types = _types()
    return types["geometry_msgs/msg/TransformStamped"](
        header=header(stamp_ns, parent),
        child_frame_id=child,
        transform=types["geometry_msgs/msg/Transform"](
            translation=_vector("Vector3", pose[:3, 3]),
            rotation=_quaternion(pose[:3, :3], wxyz),
        ),
    )


def _pairs(state: RobotState, tree: list[Joint]) -> list[tuple[str, str, Array, tuple]]:
    """(parent, child, pose in parent, its rotation's quaternion) of the base in the world,
    then of every joint."""
    q_arm = np.array(state.arm_joints)
    phi = state.base_pose[2]
    pairs = [
        (WORLD, ROOT, planar(*state.base_pose), (math.cos(phi / 2), 0.0, 0.0, math.sin(phi / 2)))
    ]
    return pairs + [
        (joint.parent, joint.child, joint.transform(q_arm), _turn(joint, q_arm)) for joint in tree
    ]


def tf_message(state: RobotState, tree: list[Joint]):
    """tf2_msgs/TFMessage: the base on the floor in the world, then every joint's transform
    at the state's joint values."""
    stamp = state.header.stamp_ns
    transforms = [transform_stamped(stamp, *pair) for pair in _pairs(state, tree)]
    return _types()["tf2_msgs/msg/TFMessage"](transforms=transforms)


def frames(state: RobotState, tree: list[Joint]) -> dict[str, Array]:
    """Every frame of the tree (the world, the base, every link) as its 4x4 pose in the world."""
    found = {WORLD: np.eye(4)}
    for parent, child, pose, _ in _pairs(state, tree):
        found[child] = found[parent] @ pose
    return found


def odometry(state: RobotState, before: RobotState | None):
    """nav_msgs/Odometry: base_footprint's pose in the world, and its twist in base_footprint
    from the state ``before`` (zero without one); covariances unknown (zero)."""
    types = _types()
    x, y, phi = state.base_pose
    twist = np.zeros(6)
    if before is not None and state.header.stamp_ns > before.header.stamp_ns:
        dt = (state.header.stamp_ns - before.header.stamp_ns) * 1e-9
        dx, dy = (x - before.base_pose[0]) / dt, (y - before.base_pose[1]) / dt
        c, s = math.cos(phi), math.sin(phi)
        turn = math.remainder(phi - before.base_pose[2], 2.0 * math.pi)
        twist[:2] = (c * dx + s * dy, -s * dx + c * dy)
        twist[5] = turn / dt
    pose = types["geometry_msgs/msg/Pose"](
        position=types["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0),
        orientation=_quaternion(planar(x, y, phi)[:3, :3]),
    )
    velocity = types["geometry_msgs/msg/Twist"](
        linear=_vector("Vector3", twist[:3]), angular=_vector("Vector3", twist[3:])
    )
    return types["nav_msgs/msg/Odometry"](
        header=header(state.header.stamp_ns, WORLD),
        child_frame_id=ROOT,
        pose=types["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
        twist=types["geometry_msgs/msg/TwistWithCovariance"](
            twist=velocity, covariance=np.zeros(36)
        ),
    )
