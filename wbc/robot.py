"""The whole-body kinematic model of chapter 4: a holonomic base model carrying a serial arm.

Configuration q = [x, y, phi, q1..qn] (m, m, rad, then rad or m per joint). The end-effector
pose is x_3^0 = x_1^0 x_2^1 x_3^2 (4.6): the base pose (4.1), the constant base-height
displacement (4.2) and the arm's product of links (4.4), each c(q_i) A_i + s(q_i) B_i whether a
DH table or a URDF chain gave it (``wbc.serial_chain``; the description is read by
``wbc.robot_description``). The nonholonomic constraint of a differential base is not in the
model: the laws impose it (5.12); a fixed base's bounds on u_b are 0.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from wbc import dq
from wbc.collision_model import CollisionModel, check_segments, collision_model
from wbc.robot_description import (
    BASE_KINDS,
    BaseDescription,
    read_arm,
    read_base,
    read_mapping,
)
from wbc.serial_chain import (
    JOINT_TYPES,
    RobotDescriptionError,
    SerialChain,
    from_dh,
    readonly,
)

__all__ = [
    "BASE_DOF",
    "BASE_KINDS",
    "JOINT_TYPES",
    "REVOLUTE",
    "BaseDescription",
    "Chain",
    "MobileManipulator",
    "RobotDescriptionError",
    "translation_jacobian",
]

Array = np.ndarray

REVOLUTE = 0.0
"""Joint type code of a revolute joint in the 5th row of the DH table (as in DQ Robotics)."""

BASE_DOF = 3


class Chain:
    """One pass of the forward kinematics at q: the end effector's pose x = x_3^0 (4.6), its
    Jacobian J = H-(x) T (4.9) and the twists T (8, dof) of ``MobileManipulator.kinematics``;
    and, when first read, the poses x_i (n + 1, 8) of the base top and of every arm frame (the
    last is x) and their Jacobians. Frame i moves with the base and joints 1..i: J_i = H-(x_i) T
    with the columns of joints i + 1..n zero (``columns``). A plain class with slots and the
    frames' arrays built when read: the LP step builds one whether any row reads the frames or
    not (as a frozen dataclass stacking the poses at once, ``kinematics`` took 31 us of CPU
    against 25 us before it; so, as before)."""

    __slots__ = ("_frame_jacobians", "_poses", "_prefixes", "columns", "jacobian", "pose", "twists")

    def __init__(self, prefixes: Array, pose: Array, twists: Array, columns: Array) -> None:
        self._prefixes, self.pose, self.twists = prefixes, pose, twists
        self.columns = columns
        """(n + 1, 1, dof): True where column j of u moves frame i."""
        self.jacobian = dq.haminus8(pose) @ twists
        self._poses: Array | None = None
        self._frame_jacobians: Array | None = None

    @property
    def poses(self) -> Array:
        """x_i of every frame (n + 1, 8): the first column of H+(x_i), then x."""
        if self._poses is None:
            count = len(self._prefixes)
            self._poses = np.empty((count + 1, 8))
            self._poses[:count] = self._prefixes[:, :, 0]
            self._poses[count] = self.pose
        return self._poses

    @property
    def frame_jacobians(self) -> Array:
        """J_i = H-(x_i) T, columns of the joints after frame i zero: (n + 1, 8, dof)."""
        if self._frame_jacobians is None:
            self._frame_jacobians = dq.haminus8_stack(self.poses) @ self.twists
            self._frame_jacobians *= self.columns
        return self._frame_jacobians


class MobileManipulator:
    """Forward kinematics (4.6), pose Jacobian (4.9) and translation Jacobian (4.18) of a base
    (``BASE_KINDS``) carrying a serial arm of revolute and prismatic joints
    (``wbc.serial_chain``: a DH table's or a URDF chain's)."""

    def __init__(
        self,
        chain: Array | SerialChain,
        base: BaseDescription,
        joint_min: Array,
        joint_max: Array,
        arm_velocity_max: Array,
        name: str = "robot",
        collision: CollisionModel = CollisionModel(),  # noqa: B008 (frozen, so sharing is safe)
        joint_names: tuple[str, ...] | None = None,
    ) -> None:
        self.name = name
        self.chain = chain if isinstance(chain, SerialChain) else from_dh(chain, joint_names)
        self.dh = self.chain.dh
        """The DH table (5, n) when one gave the arm, else None."""
        self.arm_dof = self.chain.dof
        self.dof = BASE_DOF + self.arm_dof
        self.joint_names = self.chain.names
        """The arm joints' names, as the description names them (a DH table's: q1..qn)."""
        self.joint_types = self.chain.types
        """``JOINT_TYPES`` of each arm joint."""
        if base.kind not in BASE_KINDS:
            raise RobotDescriptionError(f"base.kind: expected one of {BASE_KINDS}, got {base.kind}")
        if base.kind == "fixed" and np.any(base.velocity_max != 0.0):
            raise RobotDescriptionError("base.velocity_max: a fixed base never moves: give zeros")
        self.base = base
        self.base_height = base.height
        inf = np.full(BASE_DOF, np.inf)
        self.q_min = readonly(np.concatenate((-inf, joint_min)), (self.dof,), "joint_min", True)
        self.q_max = readonly(np.concatenate((inf, joint_max)), (self.dof,), "joint_max", True)
        if np.any(self.q_min > self.q_max):
            raise RobotDescriptionError("joint_min must not exceed joint_max")
        self.velocity_max = readonly(
            np.concatenate((base.velocity_max, arm_velocity_max)), (self.dof,), "velocity_max"
        )
        self._link_cos, self._link_sin = self.chain.link_cos, self.chain.link_sin
        prismatic = self.chain.prismatic
        self._prismatic = prismatic if prismatic.any() else None
        self._axis_ops, self._shared_axis = self.chain.axis_ops, self.chain.shared_axis
        self._frame_columns = (
            np.arange(self.dof)[None, None, :]
            < BASE_DOF + np.arange(self.arm_dof + 1)[:, None, None]
        )
        """Which columns of u move frame i: the base's and those of joints 1..i."""
        check_segments(self, collision)
        self.collision = collision
        """The parts that obstacles in 3-D must clear (``wbc.collision_model``)."""

    def joint_box(self, safety_factor: float) -> tuple[Array, Array]:
        """b_l [q-, q+] of 5.14 for every entry of q: each range shrunk by ``safety_factor``
        about zero where it holds zero (the dissertation's), about its centre where it does
        not (scaled about zero, one end of such a range would lie beyond its limit); the
        base's infinite ranges stay infinite."""
        straddles = (self.q_min <= 0.0) & (self.q_max >= 0.0)
        with np.errstate(invalid="ignore"):  # the base's -inf + inf, where the range holds 0
            centre = np.where(straddles, 0.0, 0.5 * (self.q_min + self.q_max))
        low = centre + safety_factor * (self.q_min - centre)
        high = centre + safety_factor * (self.q_max - centre)
        return low, high

    def with_velocity_max(self, velocity_max: Array) -> MobileManipulator:
        """The same robot with other bounds on u (section 6.3's tests impose none); a fixed
        base's stay 0."""
        bounds = np.array(velocity_max, dtype=float)
        if self.base.kind == "fixed":
            bounds[:BASE_DOF] = 0.0
        base = replace(
            self.base, velocity_max=readonly(bounds[:BASE_DOF], (3,), "base.velocity_max")
        )
        return MobileManipulator(
            self.chain,
            base,
            self.q_min[BASE_DOF:].copy(),
            self.q_max[BASE_DOF:].copy(),
            bounds[BASE_DOF:],
            self.name,
            self.collision,
        )

    @classmethod
    def from_yaml(cls, path: str | Path) -> MobileManipulator:
        """Build the model from a robot description such as deploy/robots/little_john.yaml
        (``wbc.robot_description``); ``RobotDescriptionError`` naming the file and the field."""
        path = Path(path)
        data = read_mapping(path)
        try:
            arm = read_arm(data, path.parent)
            return cls(
                arm.chain,
                read_base(data),
                arm.joint_min,
                arm.joint_max,
                arm.velocity_max,
                name=str(data.get("name", path.stem)),
                collision=collision_model(data.get("collision"), arm.chain.dof + 1),
            )
        except (KeyError, TypeError, ValueError) as error:
            if isinstance(error, RobotDescriptionError):
                raise RobotDescriptionError(f"{path}: {error}") from None
            raise RobotDescriptionError(f"{path}: missing or invalid field: {error}") from None

    def _check(self, q: Array) -> Array:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.dof,):
            raise ValueError(f"configuration must have shape ({self.dof},), got {q.shape}")
        return q

    def base_pose(self, q: Array) -> Array:
        """x_2^0 = x_1^0 x_2^1: base pose (4.1) raised by the base height (4.2)."""
        x, y, phi = q[0], q[1], q[2]
        c, s, z = math.cos(0.5 * phi), math.sin(0.5 * phi), self.base.height
        # D = (1/2) p r with p = x i + y j + z k and r = c + s k.
        return np.array(
            [
                c,
                0.0,
                0.0,
                s,
                -0.5 * z * s,
                0.5 * (x * c + y * s),
                0.5 * (y * c - x * s),
                0.5 * z * c,
            ]
        )

    def _arm_link_operators(self, q_arm: Array) -> Array:
        """H+(x_i^{i-1}) = c(q_i) A_i + s(q_i) B_i for every arm link (``wbc.serial_chain``)."""
        half = 0.5 * q_arm[:, None, None]
        if self._prismatic is None:
            return np.cos(half) * self._link_cos + np.sin(half) * self._link_sin
        c, s = np.cos(half), np.sin(half)
        c[self._prismatic] = 1.0
        s[self._prismatic] = q_arm[self._prismatic, None, None]
        return c * self._link_cos + s * self._link_sin

    def kinematics(self, q: Array) -> tuple[Array, Array]:
        """(vec8 x, J) for configuration q: the pose x = x_3^0 (4.6) and its Jacobian (4.9).

        x' = (x_1^0' x_1^0*) x + sum_i (1/2) z_i x q_i', where z_i = x_{0,i-1} k x_{0,i-1}*
        is the axis of joint i, so J = H-(x) T with the twists T = [H-(x_1^0*) J_b, z_i / 2];
        H-(x) T equals [H-(x_3^1) J_b, H+(x_2^0) J_a] of eq. 4.9 term by term. With J_b of
        eq. 4.3, the base twists x_1^0' x_1^0* are eps i/2 for x', eps j/2 for y' and
        k/2 + eps (y i - x j)/2 for phi'.
        """
        chain = self.forward(q)
        return chain.pose, chain.jacobian

    def forward(self, q: Array) -> Chain:
        """The pose of every frame of ``frames`` and the twists T of ``kinematics``, in one
        pass: the end effector's (x, J) and every frame's, the task's and the collision
        parts' alike (``Chain``)."""
        q = self._check(q)
        links = self._arm_link_operators(q[BASE_DOF:])
        n = self.arm_dof
        prefixes = np.empty((n, 8, 8))
        prefixes[0] = dq.hamiplus8(self.base_pose(q))
        for i in range(1, n):
            prefixes[i] = prefixes[i - 1] @ links[i - 1]
        pose = prefixes[n - 1] @ links[n - 1][:, 0]
        return Chain(prefixes, pose, self._twists(q, prefixes), self._frame_columns)

    def _twists(self, q: Array, prefixes: Array) -> Array:
        """T (8 x dof), the twists of kinematics' docstring, from H+ of the poses before each
        arm joint (``prefixes``, n x 8 x 8)."""
        # vec(x L x*) = H+(x) H+(L) C8 vec(x), for every prefix pose x = H+(x) e_1.
        if self._shared_axis is not None:
            axes = np.matmul(prefixes, (self._shared_axis @ prefixes[:, :, 0].T).T[:, :, None])
        else:
            axes = np.matmul(prefixes, np.matmul(self._axis_ops, prefixes[:, :, :1]))
        twists = np.zeros((8, self.dof))
        twists[5, 0] = twists[6, 1] = twists[3, 2] = 0.5
        twists[5, 2], twists[6, 2] = 0.5 * q[1], -0.5 * q[0]
        twists[:, BASE_DOF:] = axes[:, :, 0].T
        return twists

    def frame_kinematics(self, q: Array) -> tuple[Array, Array]:
        """The poses (n + 1, 8) of ``frames`` and their pose Jacobians (n + 1, 8, dof): frame i
        moves with the base and joints 1..i, J_i = H-(x_i) T with the columns of joints
        i + 1..n zero (the twists T of ``kinematics``); the last is (x, J) of eq. 4.9."""
        chain = self.forward(q)
        return chain.poses, chain.frame_jacobians

    def frames(self, q: Array) -> list[Array]:
        """Poses of the base top x_2^0 and of every arm frame after it; the last is x_3^0."""
        q = self._check(q)
        poses = [self.base_pose(q)]
        for link in self._arm_link_operators(q[BASE_DOF:]):
            poses.append(dq.mul(poses[-1], link[:, 0]))
        return poses

    def link_transforms(self, q: Array) -> list[Array]:
        """Each frame of ``frames(q)`` in the one before it, the first in the base frame x_1^0:
        the base top x_2^1 (4.2), then every arm link x_i^{i-1} (4.4; for a DH link r_z(q_i)
        r_theta p_d p_a r_alpha). After the planar base pose (4.1) their product is
        ``frames(q)``."""
        q = self._check(q)
        top = dq.pose(dq.ONE[:4], [0.0, 0.0, self.base.height])
        return [top, *(link[:, 0].copy() for link in self._arm_link_operators(q[BASE_DOF:]))]

    def link_outline(self, link: int) -> Array:
        """The arm link ``link`` (1 to arm_dof) as three points (3, 3) in its own frame i, m,
        fixed there whatever q_i: for a DH link the origin of frame i-1, the point d along
        z_{i-1} from it and the origin of frame i; for a URDF link the foot of frame i-1's
        origin on the joint's axis, the joint's origin and frame i's (``wbc.serial_chain``; a
        prismatic link is drawn as at q_i = 0)."""
        return self.chain.outlines[link - 1].copy()

    def fkm(self, q: Array) -> Array:
        """vec8 of the end-effector pose x_3^0 = x_1^0 x_2^1 x_3^2 (4.6)."""
        return self.frames(q)[-1]

    def pose_jacobian(self, q: Array) -> Array:
        """The 8 x dof whole-body pose Jacobian J of eq. 4.9."""
        return self.kinematics(q)[1]

    def translation_jacobian(self, q: Array) -> Array:
        """J_p of eq. 4.18 (4 x dof), with vec4(p)' = J_p q'."""
        pose, jacobian = self.kinematics(q)
        return translation_jacobian(pose, jacobian)

    def link_points(self, q: Array) -> Array:
        """World positions (n + 1, 3) of the base top and every arm frame's origin."""
        return np.array([dq.translation(pose)[1:] for pose in self.frames(q)])


def translation_jacobian(pose: Array, jacobian: Array) -> Array:
    """J_p = 2 H-_4(P(x*)) J_D + 2 H+_4(D(x)) C4 J_P (4.14-4.18), rows of vec4(p)'."""
    return 2.0 * (
        dq.haminus4(dq.qconj(pose[:4])) @ jacobian[4:]
        + dq.hamiplus4(pose[4:]) @ (dq.C4 @ jacobian[:4])
    )
