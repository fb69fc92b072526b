"""Reading a robot description, deploy/robots/<name>.yaml: the arm as a DH table or a URDF
chain (``wbc.urdf_chain``), its joints' bounds, and the base (``BASE_KINDS``).

    arm:  dh: {theta, d, a, alpha, type (revolute | prismatic), names (optional)}
          joint_min, joint_max, velocity_max
      or  urdf: {file (beside the description), base_link, tip_link}   (bounds from the URDF)
          velocity_max (optional: a commanded cap under the URDF's velocity limits)
    base: kind (differential by default), height, body_radius, velocity_max (not for fixed);
          a differential base's wheel_base, wheel_diameter, wheel_speed_max

A description that cannot be used is refused before anything starts, naming the field.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from wbc.serial_chain import JOINT_TYPES, RobotDescriptionError, SerialChain, from_dh, readonly
from wbc.urdf_chain import read_urdf_arm
from wbc.yaml_text import error_place, parse_yaml

Array = np.ndarray

BASE_KINDS = ("differential", "omnidirectional", "fixed")
"""differential: nonholonomic (the 5.12 row); omnidirectional: holonomic; fixed: never moves."""
WHEEL_FIELDS = ("wheel_base", "wheel_diameter", "wheel_speed_max")
"""A differential base's, and only its."""


@dataclass(frozen=True, kw_only=True)
class BaseDescription:
    """The base: its kind, geometry and the bounds on u_b = [x', y', phi'] (all 0 for a fixed
    base); the wheel fields are a differential base's (None for the others)."""

    height: float
    body_radius: float
    velocity_max: Array
    kind: str = "differential"
    wheel_base: float | None = None
    wheel_radius: float | None = None
    wheel_speed_max: float | None = None


@dataclass(frozen=True)
class ArmDescription:
    """The arm's chain and its joints' bounds."""

    chain: SerialChain
    joint_min: Array
    joint_max: Array
    velocity_max: Array


def read_mapping(path: Path) -> dict:
    """The YAML mapping in the file at ``path``; ``RobotDescriptionError`` naming the file if it
    is not text, not YAML or not a mapping (``OSError`` if it cannot be read)."""
    try:
        data = parse_yaml(path.read_bytes().decode("utf-8"), str(path))
    except UnicodeDecodeError as error:
        raise RobotDescriptionError(f"{path}: not UTF-8 text (byte {error.start})") from None
    except yaml.YAMLError as error:
        problem = getattr(error, "problem", None) or str(error).splitlines()[0]
        raise RobotDescriptionError(
            f"{error_place(error, str(path))}: not YAML: {problem}"
        ) from None
    if not isinstance(data, dict):
        found = "nothing" if data is None else f"a {type(data).__name__}"
        raise RobotDescriptionError(
            f"{path}: a robot description is a mapping (arm:, base:, ...), this file holds {found}"
        )
    return data


def _section(data: Mapping[str, Any], key: str, where: str) -> Mapping[str, Any]:
    if key not in data:
        raise RobotDescriptionError(f"{where}{key}: missing")
    if not isinstance(data[key], dict):
        raise RobotDescriptionError(f"{where}{key}: expected a mapping, got {data[key]!r}")
    return data[key]


def _field(data: Mapping[str, Any], key: str, where: str) -> Any:
    if key not in data:
        raise RobotDescriptionError(f"{where}.{key}: missing")
    return data[key]


def _number(data: Mapping[str, Any], key: str, where: str, positive: bool = True) -> float:
    value = _field(data, key, where)
    if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
        raise RobotDescriptionError(f"{where}.{key}: expected a finite number, got {value!r}")
    if positive and value <= 0:
        raise RobotDescriptionError(f"{where}.{key}: expected a number > 0, got {value!r}")
    return float(value)


def read_base(data: Mapping[str, Any]) -> BaseDescription:
    """The ``base`` section (module docstring)."""
    base = _section(data, "base", "")
    kind = base.get("kind", "differential")
    if kind not in BASE_KINDS:
        raise RobotDescriptionError(
            f"base.kind: expected one of {', '.join(BASE_KINDS)}, got {kind!r}"
        )
    if kind == "fixed":
        velocity = readonly(base.get("velocity_max", [0.0] * 3), (3,), "base.velocity_max")
        if np.any(velocity != 0.0):
            raise RobotDescriptionError(
                "base.velocity_max: a fixed base never moves: leave it out or give [0, 0, 0]"
            )
    else:
        velocity = readonly(_field(base, "velocity_max", "base"), (3,), "base.velocity_max")
        if np.any(velocity < 0.0):
            raise RobotDescriptionError(f"base.velocity_max: must be >= 0, got {velocity.tolist()}")
    wheels: dict[str, float] = {}
    if kind == "differential":
        wheels = {
            "wheel_base": _number(base, "wheel_base", "base"),
            "wheel_radius": 0.5 * _number(base, "wheel_diameter", "base"),
            "wheel_speed_max": _number(base, "wheel_speed_max", "base"),
        }
    else:
        for key in set(WHEEL_FIELDS) & set(base):
            raise RobotDescriptionError(f"base.{key}: only a differential base has it, not {kind}")
    return BaseDescription(
        height=_number(base, "height", "base", positive=False),
        body_radius=_number(base, "body_radius", "base"),
        velocity_max=velocity,
        kind=kind,
        **wheels,
    )


def read_arm(data: Mapping[str, Any], folder: Path) -> ArmDescription:
    """The ``arm`` section, its URDF file read beside the description (module docstring)."""
    arm = _section(data, "arm", "")
    if ("dh" in arm) == ("urdf" in arm):
        raise RobotDescriptionError("arm: expected one of dh or urdf (a DH table or a URDF file)")
    if "urdf" in arm:
        urdf = _section(arm, "urdf", "arm.")
        given = sorted({"joint_min", "joint_max"} & set(arm))
        if given:
            raise RobotDescriptionError(f"arm.{given[0]}: a URDF arm's limits come from its URDF")
        ends = [str(_field(urdf, key, "arm.urdf")) for key in ("base_link", "tip_link")]
        read = read_urdf_arm(folder / str(_field(urdf, "file", "arm.urdf")), *ends)
        speed = read.velocity
        if "velocity_max" in arm:
            speed = readonly(arm["velocity_max"], (read.chain.dof,), "arm.velocity_max")
            if np.any(speed > read.velocity):
                raise RobotDescriptionError(
                    f"arm.velocity_max: a commanded cap, at most the URDF's velocity limits "
                    f"{read.velocity.tolist()}, got {speed.tolist()}"
                )
        chain, bounds = read.chain, (read.lower, read.upper, speed)
    else:
        chain = _dh_chain(_section(arm, "dh", "arm."))
        keys = ("joint_min", "joint_max", "velocity_max")
        bounds = tuple(_field(arm, key, "arm") for key in keys)
    n = chain.dof
    low, high, speed = (
        readonly(values, (n,), f"arm.{key}", allow_inf=key != "velocity_max")
        for values, key in zip(bounds, ("joint_min", "joint_max", "velocity_max"), strict=True)
    )
    if np.any(low > high):
        raise RobotDescriptionError("arm.joint_min: must not exceed joint_max")
    if np.any(speed <= 0.0):
        raise RobotDescriptionError(f"arm.velocity_max: must be > 0, got {speed.tolist()}")
    return ArmDescription(chain, low, high, speed)


def _dh_chain(table: Mapping[str, Any]) -> SerialChain:
    types = _field(table, "type", "arm.dh")
    if not isinstance(types, list) or not types or any(t not in JOINT_TYPES for t in types):
        raise RobotDescriptionError(
            f"arm.dh.type: expected a list of {' or '.join(JOINT_TYPES)}, got {types!r}"
        )
    n = len(types)
    rows = [
        readonly(_field(table, key, "arm.dh"), (n,), f"arm.dh.{key}")
        for key in ("theta", "d", "a", "alpha")
    ]
    names = table.get("names")
    if names is not None and not isinstance(names, list):
        raise RobotDescriptionError(f"arm.dh.names: expected a list of {n} names, got {names!r}")
    codes = [float(JOINT_TYPES.index(t)) for t in types]
    try:
        return from_dh(np.array([*rows, codes]), names)
    except RobotDescriptionError as error:
        raise RobotDescriptionError(f"arm.dh.{error}") from None
