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
from dataclasses import dataclass

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
    """Numbers to 17 digits, rounding noise below 1e-15 written as 0."""
    return " ".join(f"{float(v):.17g}" if abs(v) > 1e-15 else "0" for v in values)


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


@dataclass(frozen=True)
class Joint:
    """One joint of the URDF's tree: fixed, or moved by arm joint ``index`` (0-based) about or
    along ``axis`` in its own frame, placed at ``origin`` (4x4) in its parent link."""

    name: str
    kind: str
    parent: str
    child: str
    origin: Array
    axis: Array | None = None
    index: int | None = None

    def transform(self, q_arm: Array) -> Array:
        """The child link's pose in its parent's at the arm's joint values ``q_arm``."""
        if self.index is None:
            return self.origin
        value, motion = float(q_arm[self.index]), np.eye(4)
        if self.kind == "prismatic":
            motion[:3, 3] = value * self.axis
        else:
            x, y, z = self.axis
            skew = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
            motion[:3, :3] += math.sin(value) * skew + (1.0 - math.cos(value)) * skew @ skew
        return self.origin @ motion


def joints(robot: MobileManipulator, camera: tuple[str, int, Array] | None = None) -> list[Joint]:
    """The URDF's joints, parents first (the module's docstring); ``camera`` = (frame name,
    model frame 0..n it is fixed to, its 4x4 pose there) adds a camera frame."""
    found = [Joint("base_top", "fixed", ROOT, BASE, _translation([0.0, 0.0, robot.base.height]))]
    for i in range(1, robot.arm_dof + 1):
        name = robot.joint_names[i - 1]
        before, axis, after = joint_placement(robot, i)
        kind = robot.joint_types[i - 1]
        low, high = robot.q_min[BASE_DOF + i - 1], robot.q_max[BASE_DOF + i - 1]
        if kind == "revolute" and not (np.isfinite(low) and np.isfinite(high)):
            kind = "continuous"
        separate = not np.allclose(after, np.eye(4), rtol=0.0, atol=_IDENTITY_TOLERANCE)
        child = f"{name}_motion" if separate else link_name(i)
        found.append(Joint(name, kind, link_name(i - 1), child, before, axis, i - 1))
        if separate:
            found.append(Joint(f"{name}_frame", "fixed", child, link_name(i), after))
    found.append(Joint(END_EFFECTOR, "fixed", link_name(robot.arm_dof), END_EFFECTOR, np.eye(4)))
    if camera is not None:
        frame, parent, pose = camera
        found.append(Joint(frame, "fixed", link_name(parent), frame, np.asarray(pose, float)))
    return found


def urdf(robot: MobileManipulator, camera: tuple[str, int, Array] | None = None) -> str:
    """The URDF text of ``robot`` (``joints``' tree, each arm link drawn along its outline)."""
    root = ET.Element("robot", name=robot.name)
    ET.SubElement(root, "link", name=ROOT)
    for joint in joints(robot, camera):
        link = ET.SubElement(root, "link", name=joint.child)
        if joint.child == BASE and robot.base.height > 0.0 and robot.base.body_radius > 0.0:
            below = np.array([0.0, 0.0, -robot.base.height])
            _cylinder(link, below, np.zeros(3), robot.base.body_radius)
        elif joint.child.startswith("link_"):
            outline = robot.link_outline(int(joint.child.removeprefix("link_")))
            for start, end in zip(outline[:-1], outline[1:], strict=True):
                _cylinder(link, start, end, LINK_RADIUS)
        element = ET.SubElement(root, "joint", name=joint.name, type=joint.kind)
        _origin(element, joint.origin)
        ET.SubElement(element, "parent", link=joint.parent)
        ET.SubElement(element, "child", link=joint.child)
        if joint.index is not None:
            ET.SubElement(element, "axis", xyz=_numbers(joint.axis))
            k = BASE_DOF + joint.index
            limit = {"effort": "0", "velocity": _numbers([robot.velocity_max[k]])}
            if joint.kind != "continuous":
                limit |= {"lower": _numbers([robot.q_min[k]]), "upper": _numbers([robot.q_max[k]])}
            ET.SubElement(element, "limit", limit)
    ET.indent(root)
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


URDF_URI = "package://parsimony/urdf/robot.urdf"
"""Where Foxglove's URDF panel finds the robot (its URL setting): the live view serves it."""


def assets(robot: MobileManipulator) -> dict[str, bytes]:
    """What the live view serves Foxglove's clients (``view.live_view``): the robot's URDF at
    ``URDF_URI``, the file /robot_description carries."""
    return {URDF_URI: urdf(robot).encode()}
