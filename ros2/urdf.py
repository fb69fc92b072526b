"""The robot's URDF, generated from its description (``wbc.robot.MobileManipulator``), for
rviz2's RobotModel, ``/robot_description`` and Foxglove's URDF panel.

Its tree: ``base_footprint`` (the planar base pose x_1^0; the base's motion is not in the URDF,
ROS 2 gives it on /odom and /tf), ``base_link`` (the base top x_2^0, a cylinder of the body's
radius below it), ``link_1`` .. ``link_n`` (the model's arm frames, each drawn as cylinders along
its outline) and ``end_effector`` at the last. Arm link i is x_i^{i-1}(q) = P R(q) Q: its joint
(named as the description names it) sits at P in frame i-1 and turns about (or slides along)
its axis; when Q is not the identity a fixed joint ``<joint>_frame`` carries link i at Q from
the joint's own link ``<joint>_motion``. An optional camera frame is a fixed child of a link."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from wbc import dq
from wbc.robot import BASE_DOF, MobileManipulator

Array = np.ndarray

LINK_RADIUS = 0.02
"""The radius of the cylinders an arm link is drawn with, m."""
ROOT = "base_footprint"
BASE = "base_link"
END_EFFECTOR = "end_effector"
_IDENTITY_TOLERANCE = 1e-12


def link_name(i: int) -> str:
    """The URDF link of the model's frame i (0: the base top)."""
    return BASE if i == 0 else f"link_{i}"


def matrix(x: Array) -> Array:
    """The 4x4 homogeneous transform of a unit dual quaternion."""
    result = np.eye(4)
    result[:3, :3] = dq.rotation_matrix(x[:4])
    result[:3, 3] = dq.translation(x)[1:]
    return result


def planar(x: float, y: float, phi: float) -> Array:
    """The 4x4 transform of the base pose (x, y, phi) on the floor."""
    c, s = math.cos(phi), math.sin(phi)
    return np.array([[c, -s, 0, x], [s, c, 0, y], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _translation(p: Array) -> Array:
    result = np.eye(4)
    result[:3, 3] = p
    return result


def joint_placement(robot: MobileManipulator, i: int) -> tuple[Array, Array, Array]:
    """(P, axis, Q) of arm link i (1..n) with x_i^{i-1}(q) = P R(q) Q: P a translation onto the
    joint's axis in frame i-1, R the rotation about (or translation along) the unit axis,
    found from the link at two joint values."""
    q = np.zeros(robot.dof)
    at_zero = matrix(robot.link_transforms(q)[i])
    q[BASE_DOF + i - 1] = 1.0
    motion = matrix(robot.link_transforms(q)[i]) @ np.linalg.inv(at_zero)  # in frame i-1
    if robot.joint_types[i - 1] == "prismatic":
        return np.eye(4), motion[:3, 3], at_zero
    rotation = motion[:3, :3]
    skew = rotation - rotation.T
    axis = np.array([skew[2, 1], skew[0, 2], skew[1, 0]]) / (2.0 * math.sin(1.0))
    # t = (I - R) c for every point c of the axis; the least-norm c is the foot of the origin.
    point = np.linalg.lstsq(np.eye(3) - rotation, motion[:3, 3], rcond=None)[0]
    return _translation(point), axis / np.linalg.norm(axis), _translation(-point) @ at_zero


def _rpy(rotation: Array) -> tuple[float, float, float]:
    """URDF's roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll))."""
    pitch = math.atan2(-rotation[2, 0], math.hypot(rotation[0, 0], rotation[1, 0]))
    if math.hypot(rotation[0, 0], rotation[1, 0]) < 1e-9:  # gimbal lock: roll absorbed by yaw
        return 0.0, pitch, math.atan2(-rotation[0, 1], rotation[1, 1])
    return (
        math.atan2(rotation[2, 1], rotation[2, 2]),
        pitch,
        math.atan2(rotation[1, 0], rotation[0, 0]),
    )


def _numbers(values) -> str:
    return " ".join(f"{float(v):.17g}" for v in values)


def _origin(parent: ET.Element, transform: Array) -> None:
    ET.SubElement(
        parent, "origin", xyz=_numbers(transform[:3, 3]), rpy=_numbers(_rpy(transform[:3, :3]))
    )


def _cylinder(link: ET.Element, start: Array, end: Array, radius: float) -> None:
    """A visual cylinder from ``start`` to ``end`` (its z axis along them)."""
    direction = end - start
    length = float(np.linalg.norm(direction))
    if length < 1e-9:
        return
    z = direction / length
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    placement = np.eye(4)
    placement[:3, :3] = np.column_stack((x, np.cross(z, x), z))
    placement[:3, 3] = 0.5 * (start + end)
    visual = ET.SubElement(link, "visual")
    _origin(visual, placement)
    geometry = ET.SubElement(visual, "geometry")
    ET.SubElement(geometry, "cylinder", radius=_numbers([radius]), length=_numbers([length]))


def _fixed(robot_xml: ET.Element, name: str, parent: str, child: str, transform: Array) -> None:
    joint = ET.SubElement(robot_xml, "joint", name=name, type="fixed")
    _origin(joint, transform)
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=child)


def urdf(robot: MobileManipulator, camera: tuple[str, int, Array] | None = None) -> str:
    """The URDF text of ``robot``; ``camera`` = (frame name, model frame 0..n it is fixed to,
    its 4x4 pose there) adds a camera frame."""
    root = ET.Element("robot", name=robot.name)
    ET.SubElement(root, "link", name=ROOT)
    base = ET.SubElement(root, "link", name=BASE)
    height = robot.base.height
    if height > 0.0 and robot.base.body_radius > 0.0:
        start, end = np.array([0.0, 0.0, -height]), np.zeros(3)
        _cylinder(base, start, end, robot.base.body_radius)
    _fixed(root, "base_top", ROOT, BASE, _translation([0.0, 0.0, height]))
    for i in range(1, robot.arm_dof + 1):
        name = robot.joint_names[i - 1]
        before, axis, after = joint_placement(robot, i)
        low, high = robot.q_min[BASE_DOF + i - 1], robot.q_max[BASE_DOF + i - 1]
        kind = robot.joint_types[i - 1]
        if kind == "revolute" and not (np.isfinite(low) and np.isfinite(high)):
            kind = "continuous"
        separate = not np.allclose(after, np.eye(4), rtol=0.0, atol=_IDENTITY_TOLERANCE)
        child = f"{name}_motion" if separate else link_name(i)
        if separate:
            ET.SubElement(root, "link", name=child)
        joint = ET.SubElement(root, "joint", name=name, type=kind)
        _origin(joint, before)
        ET.SubElement(joint, "parent", link=link_name(i - 1))
        ET.SubElement(joint, "child", link=child)
        ET.SubElement(joint, "axis", xyz=_numbers(axis))
        limit = {"effort": "0", "velocity": _numbers([robot.velocity_max[BASE_DOF + i - 1]])}
        if kind != "continuous":
            limit |= {"lower": _numbers([low]), "upper": _numbers([high])}
        ET.SubElement(joint, "limit", limit)
        link = ET.SubElement(root, "link", name=link_name(i))
        outline = robot.link_outline(i)
        for start, end in zip(outline[:-1], outline[1:], strict=True):
            _cylinder(link, start, end, LINK_RADIUS)
        if separate:
            _fixed(root, f"{name}_frame", child, link_name(i), after)
    ET.SubElement(root, "link", name=END_EFFECTOR)
    _fixed(root, END_EFFECTOR, link_name(robot.arm_dof), END_EFFECTOR, np.eye(4))
    if camera is not None:
        frame, parent, pose = camera
        ET.SubElement(root, "link", name=frame)
        _fixed(root, frame, link_name(parent), frame, np.asarray(pose, dtype=float))
    ET.indent(root)
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
