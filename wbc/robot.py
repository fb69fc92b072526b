"""The whole-body kinematic model of chapter 4: a holonomic base model carrying a DH arm.

Configuration q = [x, y, phi, q1..q5] (m, m, rad, rad...). The end-effector pose is
x_3^0 = x_1^0 x_2^1 x_3^2 (4.6): the base pose (4.1), the constant base-height displacement
(4.2) and the arm's DH product (4.4). The nonholonomic constraint is not in the model: the
laws impose it (5.12).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import yaml

from wbc import dq
from wbc.collision_model import CollisionModel, check_segments, collision_model

Array = np.ndarray

REVOLUTE = 0.0
"""Joint type code of a revolute joint in the 5th row of the DH table (as in DQ Robotics)."""

BASE_DOF = 3
BASE_KINDS = ("differential", "omnidirectional", "fixed")
"""differential: nonholonomic (the 5.12 row); omnidirectional: holonomic; fixed: never moves."""
JOINT_TYPES = ("revolute", "prismatic")


class RobotDescriptionError(ValueError):
    """A robot description file is missing a field or has a value of the wrong shape."""


def _readonly(values: object, shape: tuple[int, ...], what: str, allow_inf: bool = False) -> Array:
    array = np.array(values, dtype=float)
    if array.shape != shape:
        raise RobotDescriptionError(f"{what}: expected shape {shape}, got {array.shape}")
    if np.any(np.isnan(array)) or not (allow_inf or np.all(np.isfinite(array))):
        raise RobotDescriptionError(f"{what}: values must be finite, got {array.tolist()}")
    array.flags.writeable = False
    return array


def _mapping(path: Path) -> dict:
    """The YAML mapping in the file at ``path``; ``RobotDescriptionError`` naming the file if it
    is not text, not YAML or not a mapping (``OSError`` if it cannot be read)."""
    try:
        data = yaml.safe_load(path.read_bytes().decode("utf-8"))
    except UnicodeDecodeError as error:
        raise RobotDescriptionError(f"{path}: not UTF-8 text (byte {error.start})") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f"{path}:{mark.line + 1}:{mark.column + 1}" if mark else str(path)
        problem = getattr(error, "problem", None) or str(error).splitlines()[0]
        raise RobotDescriptionError(f"{where}: not YAML: {problem}") from None
    if not isinstance(data, dict):
        found = "nothing" if data is None else f"a {type(data).__name__}"
        raise RobotDescriptionError(
            f"{path}: a robot description is a mapping (arm:, base:, ...), this file holds {found}"
        )
    return data


def _dh_link(theta: float, d: float, a: float, alpha: float) -> Array:
    """r_theta p_d p_a r_alpha: one DH link Rz(theta) Tz(d) Tx(a) Rx(alpha) (4.4)."""
    r_theta = dq.from_parts(dq.rotation_quaternion(theta, [0, 0, 1]), np.zeros(4))
    p_d = dq.pose(dq.ONE[:4], [0.0, 0.0, d])
    p_a = dq.pose(dq.ONE[:4], [a, 0.0, 0.0])
    r_alpha = dq.from_parts(dq.rotation_quaternion(alpha, [1, 0, 0]), np.zeros(4))
    return dq.mul(dq.mul(dq.mul(r_theta, p_d), p_a), r_alpha)


_HALF_K = 0.5 * dq.hamiplus8(np.concatenate((dq.K_, np.zeros(4))))
_HALF_K_CONJ = _HALF_K @ dq.C8


@dataclass(frozen=True)
class BaseDescription:
    """The base: its kind (``BASE_KINDS``), geometry and the bounds on u_b = [x', y', phi']; the
    wheel fields are a differential base's."""

    height: float
    body_radius: float
    wheel_base: float
    wheel_radius: float
    wheel_speed_max: float
    velocity_max: Array
    kind: str = "differential"


class Chain:
    """One pass of the forward kinematics at q: the end effector's pose x = x_3^0 (4.6), its
    Jacobian J = H-(x) T (4.9) and the twists T (8, dof) of ``MobileManipulator.kinematics``;
    and, when first read, the poses x_i (n + 1, 8) of the base top and of every DH frame (the
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
    """Forward kinematics (4.6), pose Jacobian (4.9) and translation Jacobian (4.18)."""

    def __init__(
        self,
        dh: Array,
        base: BaseDescription,
        joint_min: Array,
        joint_max: Array,
        arm_velocity_max: Array,
        name: str = "robot",
        collision: CollisionModel = CollisionModel(),  # noqa: B008 (frozen, so sharing is safe)
        joint_names: tuple[str, ...] | None = None,
    ) -> None:
        self.name = name
        self.dh = _readonly(dh, (5, dh.shape[1]), "dh")
        if np.any(self.dh[4] != REVOLUTE):
            raise RobotDescriptionError("dh: only revolute joints are supported")
        self.arm_dof = self.dh.shape[1]
        self.joint_names = joint_names or tuple(f"q{i + 1}" for i in range(self.arm_dof))
        """The arm joints' names, as the description names them (a DH table's: q1..qn)."""
        self.joint_types = ("revolute",) * self.arm_dof
        """``JOINT_TYPES`` of each arm joint."""
        self.dof = BASE_DOF + self.arm_dof
        self.base = base
        self.base_height = base.height
        inf = np.full(BASE_DOF, np.inf)
        self.q_min = _readonly(np.concatenate((-inf, joint_min)), (self.dof,), "joint_min", True)
        self.q_max = _readonly(np.concatenate((inf, joint_max)), (self.dof,), "joint_max", True)
        if np.any(self.q_min > self.q_max):
            raise RobotDescriptionError("joint_min must not exceed joint_max")
        self.velocity_max = _readonly(
            np.concatenate((base.velocity_max, arm_velocity_max)), (self.dof,), "velocity_max"
        )
        links = np.stack([dq.hamiplus8(_dh_link(*self.dh[:4, i])) for i in range(self.arm_dof)])
        # H+(r_z(q) L) = cos(q/2) H+(L) + sin(q/2) H+(k) H+(L), with r_z(q) = cos(q/2) + k sin(q/2).
        self._link_cos = links
        self._link_sin = np.matmul(2.0 * _HALF_K, links)
        self._frame_columns = (
            np.arange(self.dof)[None, None, :]
            < BASE_DOF + np.arange(self.arm_dof + 1)[:, None, None]
        )
        """Which columns of u move frame i: the base's and those of joints 1..i."""
        check_segments(self, collision)
        self.collision = collision
        """The parts that obstacles in 3-D must clear (``wbc.collision_model``)."""

    def with_velocity_max(self, velocity_max: Array) -> MobileManipulator:
        """The same robot with other bounds on u (section 6.3's tests impose none)."""
        bounds = np.asarray(velocity_max, dtype=float)
        base = replace(
            self.base, velocity_max=_readonly(bounds[:BASE_DOF], (3,), "base.velocity_max")
        )
        return MobileManipulator(
            np.array(self.dh),
            base,
            self.q_min[BASE_DOF:].copy(),
            self.q_max[BASE_DOF:].copy(),
            bounds[BASE_DOF:],
            self.name,
            self.collision,
            self.joint_names,
        )

    @classmethod
    def from_yaml(cls, path: str | Path) -> MobileManipulator:
        """Build the model from a robot description such as deploy/robots/little_john.yaml."""
        path = Path(path)
        data = _mapping(path)
        try:
            arm, base = data["arm"], data["base"]
            table = arm["dh"]
            types = [REVOLUTE if t == "revolute" else -1.0 for t in table["type"]]
            dh = np.array([table["theta"], table["d"], table["a"], table["alpha"], types], float)
            description = BaseDescription(
                height=float(base["height"]),
                body_radius=float(base["body_radius"]),
                wheel_base=float(base["wheel_base"]),
                wheel_radius=0.5 * float(base["wheel_diameter"]),
                wheel_speed_max=float(base["wheel_speed_max"]),
                velocity_max=_readonly(base["velocity_max"], (3,), "base.velocity_max"),
            )
            return cls(
                dh,
                description,
                np.array(arm["joint_min"], float),
                np.array(arm["joint_max"], float),
                np.array(arm["velocity_max"], float),
                name=str(data.get("name", path.stem)),
                collision=collision_model(data.get("collision"), dh.shape[1] + 1),
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
        """H+(x_i) for every arm link, x_i = r_z(q_i) (r_theta_i p_d_i p_a_i r_alpha_i)."""
        half = 0.5 * q_arm[:, None, None]
        return np.cos(half) * self._link_cos + np.sin(half) * self._link_sin

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
        # vec(x k x*) = H+(x) H+(k) C8 vec(x), for every prefix pose x = H+(x) e_1.
        axes = np.matmul(prefixes, (_HALF_K_CONJ @ prefixes[:, :, 0].T).T[:, :, None])
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
        """Poses of the base top x_2^0 and of every DH frame after it; the last is x_3^0."""
        q = self._check(q)
        poses = [self.base_pose(q)]
        for link in self._arm_link_operators(q[BASE_DOF:]):
            poses.append(dq.mul(poses[-1], link[:, 0]))
        return poses

    def link_transforms(self, q: Array) -> list[Array]:
        """Each frame of ``frames(q)`` in the one before it, the first in the base frame x_1^0:
        the base top x_2^1 (4.2), then every DH link x_i^{i-1} = r_z(q_i) r_theta p_d p_a
        r_alpha (4.4). After the planar base pose (4.1) their product is ``frames(q)``."""
        q = self._check(q)
        top = dq.pose(dq.ONE[:4], [0.0, 0.0, self.base.height])
        return [top, *(link[:, 0].copy() for link in self._arm_link_operators(q[BASE_DOF:]))]

    def link_outline(self, link: int) -> Array:
        """The DH link ``link`` (1 to arm_dof) as three points (3, 3) in its own frame i, m:
        the origin of frame i-1, the point d along z_{i-1} from it, and the origin of frame i.

        Frame i-1's origin is at R_x(alpha)^T Rz(theta)^T (-Rz(theta) (a, 0, d)) =
        -(a, d sin alpha, d cos alpha) from frame i's, whatever q_i (a rotation about z_{i-1}
        turns the whole link); the point after d is -(a, 0, 0)."""
        _, d, a, alpha = self.dh[:4, link - 1]
        origin_before = -np.array([a, d * math.sin(alpha), d * math.cos(alpha)])
        return np.array([origin_before, [-a, 0.0, 0.0], [0.0, 0.0, 0.0]])

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
        """World positions (n + 1, 3) of the base top and every DH frame origin."""
        return np.array([dq.translation(pose)[1:] for pose in self.frames(q)])


def translation_jacobian(pose: Array, jacobian: Array) -> Array:
    """J_p = 2 H-_4(P(x*)) J_D + 2 H+_4(D(x)) C4 J_P (4.14-4.18), rows of vec4(p)'."""
    return 2.0 * (
        dq.haminus4(dq.qconj(pose[:4])) @ jacobian[4:]
        + dq.hamiplus4(pose[4:]) @ (dq.C4 @ jacobian[:4])
    )
