"""The robot in Foxglove's 3-D panel, from the robot description and the controller's own
kinematics (``wbc.robot``), as rviz draws a robot from its URDF and its TF tree.

Frames, for a configuration q = [x, y, phi, arm joints...] of any arm, named with a ``prefix``
(``estimate/``, ``truth/``, ``candidate/``), each in the one before it::

    <parent> -> <prefix>base      the planar base pose (x, y, phi) on the floor (4.1)
    base     -> <prefix>link_0    the base top, where the arm stands (4.2)
    link_i-1 -> <prefix>link_i    the arm's link i (4.4), i = 1..n; link_n is the end effector

The model is a ``foxglove.SceneUpdate`` of primitives fixed in those frames (``frame_locked``):
the base as a disc of its radius and height with an arrow to its front, and its wheels by its
kind (a differential base's two on the axle, an omnidirectional base's four at the corners, a
fixed base's none); each revolute link as a thick line through its outline
(``MobileManipulator.link_outline``) with a sphere at the joint; each prismatic link as its rail
in the frame before it (where its frame's origin runs over the joint's travel) and a sphere, the
carriage, at its frame's origin; and two fingers at the end effector. Its primitives never change;
only the transforms move them. Why primitives and not a URDF served by the server's asset
handler: a recording carries them as it carries everything else, so a session file shows the
robot in Foxglove with no server behind it, and the live view and the file draw the same.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from foxglove import messages as fox

from scenes.foxglove_frames import planar_transform, pose_transform, timestamp
from wbc import dq
from wbc.robot import BASE_DOF, MobileManipulator

LINK_THICKNESS_M = 0.03
"""How thick an arm link is drawn."""
JOINT_DIAMETER_M = 0.045
WHEEL_WIDTH_M = 0.02
FINGER_SIZE_M = (0.06, 0.012, 0.025)
"""A finger (x along the last link, y across the gripper, z), m."""
FINGER_GAP_M = 0.04
"""Between the fingers' centres."""
WHEEL_COLOR = fox.Color(r=0.15, g=0.15, b=0.15, a=1.0)
OMNI_WHEEL_RADIUS_M = 0.05
"""An omnidirectional base's wheels when its description gives no wheel size."""
IDENTITY = fox.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)
ORIGIN = np.zeros(3)
AXLE = fox.Quaternion(x=math.sin(math.pi / 4), y=0.0, z=0.0, w=math.cos(math.pi / 4))
"""A cylinder's axis (z) turned onto the wheel axle (y)."""


def point(p: np.ndarray) -> fox.Point3:
    return fox.Point3(x=float(p[0]), y=float(p[1]), z=float(p[2]))


def at(x: float, y: float, z: float, orientation: fox.Quaternion = IDENTITY) -> fox.Pose:
    return fox.Pose(position=fox.Vector3(x=x, y=y, z=z), orientation=orientation)


@dataclass(frozen=True)
class RobotDrawing:
    """One robot of the 3-D panel: its frames named ``<prefix>...``, under ``parent``, drawn
    in ``color``."""

    robot: MobileManipulator
    prefix: str
    color: fox.Color
    parent: str = "world"

    def frame(self, name: str) -> str:
        return self.prefix + name

    def links(self) -> list[str]:
        """Every frame of the robot below its base: link_0 (the base top) to link_n."""
        return [self.frame(f"link_{i}") for i in range(self.robot.arm_dof + 1)]

    def configuration(self, message: Any) -> np.ndarray:
        """The q of a state or a truth (``configuration()``) of this robot; ``ValueError``
        naming both when its joints are not the description's (by name, when it names them)."""
        names = tuple(getattr(message, "joint_names", None) or ())
        expected = self.robot.joint_names
        if (names and names != expected) or len(message.arm_joints) != len(expected):
            found = ", ".join(names) or f"{len(message.arm_joints)} unnamed"
            raise ValueError(
                f"its arm joints are {found}; the robot description's are {', '.join(expected)}"
            )
        return np.array(message.configuration())

    def transforms(self, q: np.ndarray, stamp_ns: int) -> list[fox.FrameTransform]:
        """The base on the floor, then every link in the one before it, at configuration q."""
        found = [planar_transform(self.parent, self.frame("base"), tuple(q[:BASE_DOF]), stamp_ns)]
        links = self.links()
        for parent, child, pose in zip(
            [self.frame("base"), *links[:-1]], links, self.robot.link_transforms(q), strict=True
        ):
            found.append(pose_transform(parent, child, pose, stamp_ns))
        return found

    def model(self, stamp_ns: int) -> list[fox.SceneEntity]:
        """The robot's primitives, each entity fixed in its frame."""
        stamp = timestamp(stamp_ns)
        entities = [self._entity("base", stamp, **self._base())]
        for i in range(1, self.robot.arm_dof + 1):
            if self.robot.joint_types[i - 1] == "prismatic":
                rail = self._line(self._rail(i))
                entities.append(
                    self._entity(f"link_{i - 1}", stamp, f"link_{i}_rail", lines=[rail])
                )
                entities.append(self._entity(f"link_{i}", stamp, spheres=[self._joint(ORIGIN)]))
                continue
            outline = self.robot.link_outline(i)
            line = self._line(outline)
            entities.append(
                self._entity(f"link_{i}", stamp, spheres=[self._joint(outline[0])], lines=[line])
            )
        entities.append(
            self._entity(f"link_{self.robot.arm_dof}", stamp, "gripper", cubes=self._fingers())
        )
        return entities

    def _joint(self, centre: np.ndarray) -> fox.SpherePrimitive:
        return fox.SpherePrimitive(
            pose=at(*map(float, centre)),
            color=self.color,
            size=fox.Vector3(x=JOINT_DIAMETER_M, y=JOINT_DIAMETER_M, z=JOINT_DIAMETER_M),
        )

    def _line(self, points: np.ndarray) -> fox.LinePrimitive:
        """A thick line through ``points`` (k, 3) of its frame."""
        return fox.LinePrimitive(
            type=fox.LinePrimitiveLineType.LineStrip,
            pose=at(0, 0, 0),
            thickness=LINK_THICKNESS_M,
            color=self.color,
            points=[point(p) for p in points],
        )

    def _rail(self, link: int) -> np.ndarray:
        """A prismatic link's rail in the frame before it (3, 3): from that frame's origin to
        where link ``link``'s frame is at the joint's lower limit, then at its upper limit."""
        joint = BASE_DOF + link - 1
        ends = []
        for limit in (self.robot.q_min[joint], self.robot.q_max[joint]):
            q = np.zeros(self.robot.dof)
            q[joint] = limit  # the link's own transform depends on its joint alone
            ends.append(dq.translation(self.robot.link_transforms(q)[link])[1:])
        return np.array([ORIGIN, *ends])

    def _entity(
        self, frame: str, stamp: fox.Timestamp, part: str = "", **primitives: list
    ) -> fox.SceneEntity:
        return fox.SceneEntity(
            timestamp=stamp,
            frame_id=self.frame(frame),
            frame_locked=True,
            id=self.frame(part or frame),
            **primitives,
        )

    def _base(self) -> dict[str, list]:
        """The base: a disc of its radius up to the arm's mount, its wheels (``wheel_centres``),
        an arrow to its front."""
        base = self.robot.base
        height, radius = base.height, base.body_radius
        disc = fox.CylinderPrimitive(
            pose=at(0.0, 0.0, height / 2),
            color=self.color,
            size=fox.Vector3(x=2 * radius, y=2 * radius, z=height),
            bottom_scale=1.0,
            top_scale=1.0,
        )
        wheel = base.wheel_radius or OMNI_WHEEL_RADIUS_M
        wheels = [
            fox.CylinderPrimitive(
                pose=at(x, y, wheel, AXLE),
                size=fox.Vector3(x=2 * wheel, y=2 * wheel, z=WHEEL_WIDTH_M),
                bottom_scale=1.0,
                top_scale=1.0,
                color=WHEEL_COLOR,
            )
            for x, y in wheel_centres(self.robot)
        ]

        front = fox.ArrowPrimitive(
            pose=at(0.0, 0.0, height + 0.01),
            shaft_length=0.7 * radius,
            shaft_diameter=0.02,
            head_length=0.25 * radius,
            head_diameter=0.05,
            color=self.color,
        )
        return {"cylinders": [disc, *wheels], "arrows": [front]}

    def _fingers(self) -> list[fox.CubePrimitive]:
        """Two fingers either side of the end effector, along the last link (its x axis)."""
        length, width, height = FINGER_SIZE_M
        size = fox.Vector3(x=length, y=width, z=height)
        return [
            fox.CubePrimitive(
                pose=at(-length / 2, side * FINGER_GAP_M / 2, 0.0), size=size, color=self.color
            )
            for side in (-1.0, 1.0)
        ]


def wheel_centres(robot: MobileManipulator) -> list[tuple[float, float]]:
    """Where the base's wheels touch the floor (x, y) in its frame, by its kind: a differential
    base's two on the axle, ``wheel_base`` apart; an omnidirectional base's four at the corners
    of the square inside its disc; a fixed base's none."""
    base = robot.base
    if base.kind == "fixed":
        return []
    if base.kind == "omnidirectional":
        corner = base.body_radius / math.sqrt(2.0)
        return [(sx * corner, sy * corner) for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)]
    return [(0.0, side * base.wheel_base / 2) for side in (-1.0, 1.0)]
