"""A serial arm as its constant parts, whether a DH table or a URDF chain gave it.

Link i is x_i^{i-1} = F_i M_i(q_i) G_i: a fixed transform F_i to the joint's frame, the joint's
motion M_i about (revolute) or along (prismatic) its unit axis a_i, and a fixed transform G_i
after it. With M = cos(q/2) + a sin(q/2) (revolute) or M = 1 + eps (q/2) a (prismatic),

    H+(x_i^{i-1}) = c(q_i) A_i + s(q_i) B_i,   A_i = H+(F_i) H+(G_i),
    B_i = H+(F_i) H+(a_i) H+(G_i) (revolute) or H+(F_i) H+(eps a_i / 2) H+(G_i) (prismatic),

c, s = cos(q/2), sin(q/2) (revolute) or 1, q (prismatic). Joint i turns x by the twist
(1/2) y a_i y* (revolute) or (eps/2) y a_i y* (prismatic), y = x_{i-1} F_i; that is
(1/2) x_{i-1} L_i x_{i-1}* with the constant line L_i = F_i a_i F_i* (times eps if prismatic),
vec8 = H+(x_{i-1}) ``axis_ops[i]`` vec8(x_{i-1}), axis_ops = H+(L_i) C8 / 2. A DH row
(DQ Robotics' Rz(theta + q) Tz(d + q) Tx(a) Rx(alpha)) is F = 1, a = k, G = its link (4.4).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from wbc import dq

Array = np.ndarray

JOINT_TYPES = ("revolute", "prismatic")
"""The arm joints a description may give: 0 and 1 in the 5th row of a DH table."""


class RobotDescriptionError(ValueError):
    """A robot description file is missing a field or has a value of the wrong shape."""


def readonly(values: object, shape: tuple[int, ...], what: str, allow_inf: bool = False) -> Array:
    """A read-only float array of ``shape``; ``RobotDescriptionError`` naming ``what``."""
    try:
        array = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise RobotDescriptionError(f"{what}: expected numbers, got {values!r}") from None
    if array.shape != shape:
        raise RobotDescriptionError(f"{what}: expected shape {shape}, got {array.shape}")
    if np.any(np.isnan(array)) or not (allow_inf or np.all(np.isfinite(array))):
        raise RobotDescriptionError(f"{what}: values must be finite, got {array.tolist()}")
    array.flags.writeable = False
    return array


def dh_link(theta: float, d: float, a: float, alpha: float) -> Array:
    """r_theta p_d p_a r_alpha: one DH link Rz(theta) Tz(d) Tx(a) Rx(alpha) (4.4)."""
    r_theta = dq.from_parts(dq.rotation_quaternion(theta, [0, 0, 1]), np.zeros(4))
    p_d = dq.pose(dq.ONE[:4], [0.0, 0.0, d])
    p_a = dq.pose(dq.ONE[:4], [a, 0.0, 0.0])
    r_alpha = dq.from_parts(dq.rotation_quaternion(alpha, [1, 0, 0]), np.zeros(4))
    return dq.mul(dq.mul(dq.mul(r_theta, p_d), p_a), r_alpha)


_HALF_K = 0.5 * dq.hamiplus8(np.concatenate((dq.K_, np.zeros(4))))
HALF_K_CONJ = _HALF_K @ dq.C8
"""H+(k) C8 / 2: the axis operator of every revolute DH joint."""


@dataclass(frozen=True)
class ChainJoint:
    """One movable joint of a chain given by transforms: x_i^{i-1} = F M(q) G."""

    name: str
    type: str
    before: Array
    """F, vec8: the joint's frame in the frame before it."""
    axis: Array
    """a, a unit 3-vector in the joint's frame."""
    after: Array
    """G, vec8: frame i in the joint's frame at q = 0."""


@dataclass(frozen=True)
class SerialChain:
    """The constant parts of an arm's forward kinematics (the module's docstring)."""

    names: tuple[str, ...]
    types: tuple[str, ...]
    link_cos: Array
    """A_i, (n, 8, 8)."""
    link_sin: Array
    """B_i, (n, 8, 8)."""
    axis_ops: Array
    """H+(L_i) C8 / 2, (n, 8, 8)."""
    outlines: Array
    """Each link drawn as three points in its own frame i (``MobileManipulator.link_outline``)."""
    dh: Array | None = None
    """The DH table (5, n) when one gave the chain."""

    @property
    def dof(self) -> int:
        return len(self.names)

    @property
    def prismatic(self) -> Array:
        """True for each prismatic joint."""
        return np.array([t == "prismatic" for t in self.types])

    @property
    def shared_axis(self) -> Array | None:
        """The one axis operator of every joint when they all share it (a revolute DH arm)."""
        return HALF_K_CONJ if bool(np.all(self.axis_ops == HALF_K_CONJ)) else None


def _names(names: Sequence[str] | None, n: int) -> tuple[str, ...]:
    found = tuple(str(name) for name in names) if names is not None else ()
    if names is None:
        return tuple(f"q{i + 1}" for i in range(n))
    if len(found) != n or len(set(found)) != n or not all(found):
        raise RobotDescriptionError(f"names: expected {n} different names, got {list(found)}")
    return found


def from_dh(dh: Array, names: Sequence[str] | None = None) -> SerialChain:
    """The chain of a DH table (5, n): theta, d, a, alpha, type (0 revolute, 1 prismatic)."""
    shape = np.shape(dh)
    table = readonly(dh, (5, shape[1] if len(shape) == 2 else 0), "dh")
    n = table.shape[1]
    if n < 1 or not np.all(np.isin(table[4], (0.0, 1.0))):
        raise RobotDescriptionError(
            f"dh.type: expected revolute or prismatic for each of >= 1 joints, got {table[4]}"
        )
    types = tuple(JOINT_TYPES[int(t)] for t in table[4])
    links = np.stack([dq.hamiplus8(dh_link(*table[:4, i])) for i in range(n)])
    # H+(r_z(q) L) = cos(q/2) H+(L) + sin(q/2) H+(k) H+(L),
    # H+(p_z(q) L) = H+(L) + q H+(eps k/2) H+(L).
    sines = np.matmul(2.0 * _HALF_K, links)
    half_eps_k = dq.hamiplus8(np.concatenate((np.zeros(4), 0.5 * dq.K_)))
    for i, joint_type in enumerate(types):
        if joint_type == "prismatic":
            sines[i] = half_eps_k @ links[i]
    eps_k_op = 0.5 * dq.hamiplus8(np.concatenate((np.zeros(4), dq.K_))) @ dq.C8
    ops = np.stack([HALF_K_CONJ if t == "revolute" else eps_k_op for t in types])
    outlines = np.stack([_dh_outline(*table[1:4, i]) for i in range(n)])
    return SerialChain(_names(names, n), types, links, sines, ops, outlines, table)


def _dh_outline(d: float, a: float, alpha: float) -> Array:
    """Frame i-1's origin in frame i, -(a, d sin alpha, d cos alpha) whatever q_i (a rotation
    about z_{i-1} turns the whole link), the point d along z_{i-1} from it, -(a, 0, 0), and
    frame i's origin (a prismatic joint drawn at q = 0)."""
    origin_before = -np.array([a, d * math.sin(alpha), d * math.cos(alpha)])
    return np.array([origin_before, [-a, 0.0, 0.0], [0.0, 0.0, 0.0]])


def from_joints(joints: Sequence[ChainJoint]) -> SerialChain:
    """The chain of joints given by transforms (a URDF chain)."""
    link_cos, link_sin, ops, outlines = [], [], [], []
    for joint in joints:
        before, after = dq.hamiplus8(joint.before), dq.hamiplus8(joint.after)
        axis = np.concatenate(([0.0], joint.axis))
        rotated = dq.qmul(dq.qmul(joint.before[:4], axis), dq.qconj(joint.before[:4]))
        if joint.type == "revolute":
            motion = np.concatenate((axis, np.zeros(4)))
            line = dq.mul(dq.mul(joint.before, motion), dq.conj(joint.before))
        else:
            motion = np.concatenate((np.zeros(4), 0.5 * axis))
            line = np.concatenate((np.zeros(4), rotated))
        link_cos.append(before @ after)
        link_sin.append(before @ dq.hamiplus8(motion) @ after)
        ops.append(0.5 * dq.hamiplus8(line) @ dq.C8)
        outlines.append(_outline(joint))
    names = _names([j.name for j in joints], len(joints))
    types = tuple(j.type for j in joints)
    return SerialChain(names, types, *map(np.stack, (link_cos, link_sin, ops, outlines)))


def _outline(joint: ChainJoint) -> Array:
    """In frame i: the foot of frame i-1's origin on the joint's axis (a revolute joint turns
    it about the axis, so it is fixed in frame i; a prismatic joint's frame origin instead),
    the joint's frame origin, and frame i's origin."""
    inverse = dq.conj(joint.after)  # the joint's frame in frame i, at q = 0
    origin = dq.translation(inverse)[1:]
    direction = dq.rotation_matrix(inverse[:4]) @ joint.axis
    if joint.type == "revolute":
        link = dq.mul(joint.before, joint.after)
        before = dq.translation(dq.conj(link))[1:]
        foot = origin + direction * float(np.dot(before - origin, direction))
    else:
        foot = origin
    return np.array([foot, origin, [0.0, 0.0, 0.0]])
