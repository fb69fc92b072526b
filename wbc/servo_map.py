"""The arm's servos as the robot description places them: the ``servos:`` section of a robot's
file gives, per joint (in the arm's order), the servo's bus id, its angle at the joint's zero
(``offsets``, rad) and whether it turns with the joint (``directions``, +1) or against it (-1):

    servo angle = offset + direction * q,      servo speed = direction * q'

A file without the section has servos 1..n, no offsets and every direction +1. The arm driver
(``components.arm_driver``) and the emulated servos (``components.emulated_robot``) both map
through it, so they agree byte for byte."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from wbc.robot_description import RobotDescriptionError, read_mapping

ID_MAX = 253
"""The largest id a servo may have (254 is the broadcast id)."""


@dataclass(frozen=True)
class ServoMap:
    """A servo per arm joint: ``ids``, ``offsets`` (rad) and ``directions`` (+1 or -1)."""

    ids: tuple[int, ...]
    offsets: tuple[float, ...]
    directions: tuple[int, ...]

    @classmethod
    def plain(cls, joints: int) -> ServoMap:
        """Servos 1..``joints``, each turning as its joint from the same zero."""
        return cls(tuple(range(1, joints + 1)), (0.0,) * joints, (1,) * joints)

    @classmethod
    def of(cls, path: str | Path, joints: int) -> ServoMap:
        """The ``servos:`` section of the robot description at ``path`` (an arm of ``joints``
        joints); ``RobotDescriptionError`` naming the field when it cannot be used."""
        section = read_mapping(Path(path)).get("servos")
        plain = cls.plain(joints)
        if section is None:
            return plain
        if not isinstance(section, dict):
            raise RobotDescriptionError(f"servos: expected a mapping, got {section!r}")
        unknown = sorted(set(section) - {"ids", "offsets", "directions"})
        if unknown:
            raise RobotDescriptionError(f"servos: unknown fields {unknown}")
        ids = _row(section, "ids", plain.ids, joints)
        offsets = _row(section, "offsets", plain.offsets, joints)
        directions = _row(section, "directions", plain.directions, joints)
        if not all(type(i) is int and 0 <= i <= ID_MAX for i in ids) or len(set(ids)) != joints:
            raise RobotDescriptionError(f"servos.ids: expected distinct ids in 0..253, got {ids}")
        if not all(isinstance(o, int | float) and math.isfinite(o) for o in offsets):
            raise RobotDescriptionError(f"servos.offsets: expected finite angles, got {offsets}")
        if not all(d in (1, -1) and type(d) is int for d in directions):
            raise RobotDescriptionError(f"servos.directions: expected +1 or -1, got {directions}")
        return cls(ids, tuple(float(o) for o in offsets), directions)

    def with_ids(self, ids: tuple[int, ...]) -> ServoMap:
        """The same servos answering to ``ids`` (a profile's override)."""
        return ServoMap(tuple(ids), self.offsets, self.directions)

    def servo_angle(self, joint: int, q: float) -> float:
        """The servo's angle (rad, 0 at its centre) where joint ``joint`` is at ``q``."""
        return self.offsets[joint] + self.directions[joint] * q

    def joint_position(self, joint: int, angle: float) -> float:
        """Joint ``joint``'s position where its servo is at ``angle`` (rad)."""
        return self.directions[joint] * (angle - self.offsets[joint])


def _row(section: dict, name: str, default: tuple, joints: int) -> tuple:
    row = section.get(name, default)
    if not isinstance(row, list | tuple) or len(row) != joints:
        raise RobotDescriptionError(
            f"servos.{name}: expected {joints} values, one per joint, got {row!r}"
        )
    return tuple(row)
