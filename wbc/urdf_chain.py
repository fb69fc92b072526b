"""A robot description's arm from a URDF file: the serial chain from a base link to a tip link,
read with yourdfpy, its joints' limits and velocity limits from the file.

Each movable joint on the path is F M(q) G (``wbc.serial_chain``): F its origin, after the
fixed joints since the movable one before it (folded in); M its rotation about or translation
along its axis; G the identity, but for the last joint the fixed joints from it to the tip. So
frame i is the child link of the i-th movable joint and the last frame the tip link. Joints
that branch off the path (a gripper's fingers) move nothing on it and are left out.

Refused, naming the field: a link that is not in the file, a tip not below the base (no serial
chain joins them: they lie on two branches), a continuous, floating, planar or mimic joint on
the path, a missing limit or velocity limit, a value that is not finite.
"""

from __future__ import annotations

import contextlib
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from wbc import dq
from wbc.serial_chain import ChainJoint, RobotDescriptionError, SerialChain, from_joints

if TYPE_CHECKING:
    import yourdfpy

Array = np.ndarray

MOVABLE = ("revolute", "prismatic")


@dataclass(frozen=True)
class UrdfArm:
    """The chain and its joints' bounds, as the URDF gives them."""

    chain: SerialChain
    lower: Array
    upper: Array
    velocity: Array


def load(path: Path) -> yourdfpy.Robot:
    """The URDF's robot (links and joints, no meshes); ``RobotDescriptionError`` if unreadable.
    What yourdfpy prints about a file it cannot parse goes to stderr (stdout is for JSON)."""
    import yourdfpy  # a second of CPU (trimesh, networkx): only for a URDF arm, not every start

    if not path.is_file():
        raise RobotDescriptionError(f"arm.urdf.file: no file {path}")
    try:
        with contextlib.redirect_stdout(sys.stderr):
            urdf = yourdfpy.URDF.load(
                str(path),
                build_scene_graph=False,
                load_meshes=False,
                build_collision_scene_graph=False,
                load_collision_meshes=False,
            )
    except OSError as error:
        raise RobotDescriptionError(
            f"arm.urdf.file: cannot read {path}: {error.strerror or error}"
        ) from None
    except Exception as error:  # lxml's syntax errors and yourdfpy's on a malformed element
        problem = str(error).splitlines()[0] if str(error) else type(error).__name__
        raise RobotDescriptionError(f"arm.urdf.file: {path} is not a URDF: {problem}") from None
    return urdf.robot


def read_urdf_arm(path: Path, base_link: str, tip_link: str) -> UrdfArm:
    """The serial chain of ``path`` from ``base_link`` to ``tip_link`` (module docstring)."""
    robot = load(path)
    where = f"arm.urdf ({path.name})"
    links = [link.name for link in robot.links]
    for field, link in (("base_link", base_link), ("tip_link", tip_link)):
        if link not in links:
            raise RobotDescriptionError(
                f"arm.urdf.{field}: no link {link!r} in {path.name} (its links: {', '.join(links)})"
            )
    joints = _path(robot, base_link, tip_link, where)
    chain, lower, upper, velocity = [], [], [], []
    pending = dq.ONE.copy()
    for joint in joints:
        origin = dq.mul(pending, _origin(joint, where))
        if joint.type == "fixed":
            pending = origin
            continue
        _check_movable(joint, where)
        axis = np.asarray(joint.axis, dtype=float) / np.linalg.norm(joint.axis)
        chain.append(ChainJoint(joint.name, joint.type, origin, axis, dq.ONE))
        lower.append(joint.limit.lower)
        upper.append(joint.limit.upper)
        velocity.append(joint.limit.velocity)
        pending = dq.ONE.copy()
    if not chain:
        raise RobotDescriptionError(
            f"{where}: no revolute or prismatic joint from {base_link!r} to {tip_link!r}"
        )
    last = chain[-1]
    chain[-1] = ChainJoint(last.name, last.type, last.before, last.axis, pending)
    bounds = (np.array(values, dtype=float) for values in (lower, upper, velocity))
    return UrdfArm(from_joints(chain), *bounds)


def _path(robot: yourdfpy.Robot, base_link: str, tip_link: str, where: str) -> list:
    """The joints from ``base_link`` down to ``tip_link``; refused if they are not a serial path."""
    parent_joint = {joint.child: joint for joint in robot.joints}
    found, link = [], tip_link
    while link != base_link:
        joint = parent_joint.get(link)
        if joint is None:
            raise RobotDescriptionError(
                f"arm.urdf.tip_link: {tip_link!r} is not below base_link {base_link!r} in "
                f"{where}: no serial chain joins them"
            )
        found.append(joint)
        link = joint.parent
    found.reverse()
    return found


def _origin(joint: yourdfpy.Joint, where: str) -> Array:
    """The joint's <origin> as a unit dual quaternion (none: the identity)."""
    if joint.origin is None:
        return dq.ONE.copy()
    matrix = np.asarray(joint.origin, dtype=float)
    if not np.all(np.isfinite(matrix)):
        raise RobotDescriptionError(
            f"{where}: joint {joint.name!r}: <origin> must be finite numbers"
        )
    return dq.pose(dq.quaternion_of_matrix(matrix[:3, :3]), matrix[:3, 3])


def _check_movable(joint: yourdfpy.Joint, where: str) -> None:
    """Refuse a joint the chain cannot take, naming the joint and the field."""
    field = f"{where}: joint {joint.name!r}"
    if joint.type == "continuous":
        raise RobotDescriptionError(
            f"{field}: type continuous has no limits, and a motor needs limits "
            "(give it type revolute with <limit lower upper velocity>)"
        )
    if joint.type not in MOVABLE:
        raise RobotDescriptionError(
            f"{field}: type {joint.type} is not supported (revolute, prismatic or fixed)"
        )
    if joint.mimic is not None:
        raise RobotDescriptionError(f"{field}: <mimic> joints are not supported")
    if joint.limit is None:
        raise RobotDescriptionError(f"{field}: needs a <limit> (lower, upper, velocity)")
    for name in ("lower", "upper", "velocity"):
        value = getattr(joint.limit, name)
        if value is None:
            raise RobotDescriptionError(f"{field}: <limit> needs {name}")
        if not math.isfinite(value):
            raise RobotDescriptionError(f"{field}: <limit> {name} must be finite, got {value}")
    if joint.limit.lower > joint.limit.upper:
        raise RobotDescriptionError(
            f"{field}: <limit> lower {joint.limit.lower} exceeds upper {joint.limit.upper}"
        )
    if joint.limit.velocity <= 0.0:
        raise RobotDescriptionError(
            f"{field}: <limit> velocity must be > 0, got {joint.limit.velocity}"
        )
    axis = np.asarray(joint.axis, dtype=float)
    if axis.shape != (3,) or not np.all(np.isfinite(axis)) or not np.linalg.norm(axis) > 0.0:
        raise RobotDescriptionError(
            f"{field}: <axis> must be a nonzero finite 3-vector, got {axis.tolist()}"
        )
