"""A recording's commands as control inputs u: their table, their effort, digest and CSV.

The control inputs u = [x', y', phi', a velocity per arm joint of the robot's description] join
the base and arm commands of one stamp with x' = v cos(phi) - l sin(phi), y' = v sin(phi) +
l cos(phi) (l the lateral speed of an omnidirectional base, else 0), phi the heading of the
nearest state: the estimate the controller turned u into the base's command with.
"""

from __future__ import annotations

import hashlib
import struct
from collections.abc import Mapping

import numpy as np

from analysis.run_end import Session, messages
from messages.topics import ARM_COMMAND, BASE_COMMAND, ROBOT_STATE, Topic
from wbc.laws.kinematic_run import effort_of
from wbc.robot import MobileManipulator

Array = np.ndarray

METRICS: Mapping[str, str] = {
    "metric1": "velocity_l1",
    "metric2": "velocity_l2",
    "metric3": "acceleration_l1",
    "metric4": "acceleration_l2",
}
"""Table 6.1's metrics: the ``ControlEffort`` field each reports."""


def nearest(sorted_stamps: Array, stamps: Array) -> Array:
    """The index into ``sorted_stamps`` (not empty) of the one nearest each of ``stamps``."""
    if len(sorted_stamps) == 1:
        return np.zeros(len(stamps), dtype=int)
    after = np.clip(np.searchsorted(sorted_stamps, stamps), 1, len(sorted_stamps) - 1)
    before = after - 1
    nearer_before = stamps - sorted_stamps[before] <= sorted_stamps[after] - stamps
    return np.where(nearer_before, before, after)


def commands(session: Session) -> tuple[Array, Array]:
    """(stamps in ns, u rows) of the stamps that have a base and an arm command, and a state
    to take the heading from; ``ValueError`` naming what is missing."""
    base = {m.header.stamp_ns: m for m in required(session, BASE_COMMAND)}
    arm = {m.header.stamp_ns: m for m in required(session, ARM_COMMAND)}
    stamps = np.array(sorted(base.keys() & arm.keys()), dtype=np.int64)
    if stamps.size == 0:
        raise ValueError(
            f"no {BASE_COMMAND.name!r} message shares a stamp with {ARM_COMMAND.name!r}"
        )
    states = required(session, ROBOT_STATE)
    state_stamps = np.array([s.header.stamp_ns for s in states], dtype=np.int64)
    phi = np.array([states[i].base_pose[2] for i in nearest(state_stamps, stamps)])
    v = np.array([base[s].forward_velocity for s in stamps])
    omega = np.array([base[s].angular_velocity for s in stamps])
    joints = np.array([arm[s].joint_velocities for s in stamps])
    if not any(base[s].lateral_velocity for s in stamps):  # as a differential base's always
        return stamps, np.column_stack((v * np.cos(phi), v * np.sin(phi), omega, joints))
    side = np.array([base[s].lateral_velocity for s in stamps])  # to the base's left
    cos, sin = np.cos(phi), np.sin(phi)
    return stamps, np.column_stack((v * cos - side * sin, v * sin + side * cos, omega, joints))


def required(session: Session, topic: Topic) -> list:
    """The messages of ``topic`` in stamp order; ``ValueError`` naming it when there are none
    or they are not of its type."""
    found = messages(session, topic)
    if not found:
        raise ValueError(f"the session has no messages on topic {topic.name!r}")
    wrong = [type(m).__name__ for m in found if not isinstance(m, topic.type)]
    if wrong:
        raise ValueError(f"topic {topic.name!r} carries {topic.type.__name__}, got {wrong[0]}")
    return found


def effort(session: Session) -> dict[str, float] | None:
    """Table 6.1's metrics of the control inputs, with dt the median command period, as
    ``metric1`` .. ``metric4``; None with fewer than two commands."""
    try:
        stamps, u = commands(session)
    except ValueError:
        return None
    return effort_of_inputs(stamps, u)


def effort_of_inputs(stamps_ns: Array, u: Array) -> dict[str, float] | None:
    """``effort_of`` rows of u stamped ``stamps_ns``, dt their median period."""
    if len(stamps_ns) < 2:
        return None
    metrics = effort_of(u, float(np.median(np.diff(stamps_ns))) * 1e-9)
    return {name: getattr(metrics, field) for name, field in METRICS.items()}


def commands_digest(session: Session) -> str:
    """SHA-256 of every command's stamp and values in stamp order: two runs that sent the same
    commands have the same digest (a field at its default, such as a differential base's
    ``lateral_velocity`` 0, is left out: the digests of older runs hold)."""
    digest = hashlib.sha256()
    for topic in (BASE_COMMAND, ARM_COMMAND):
        for command in messages(session, topic):
            values = command.model_dump(exclude={"header", "joint_names"}, exclude_defaults=True)
            digest.update(struct.pack("<q", command.header.stamp_ns))
            digest.update(repr(sorted(values.items())).encode())
    return digest.hexdigest()


def commands_csv(session: Session, robot: MobileManipulator) -> str:
    """Every command pair the controller sent, one row per stamp (s, m/s, rad/s), the lateral
    speed after the angular on an omnidirectional base, a column per joint of the robot's arm,
    named as its description names it (``<name>_dot``)."""
    arm = {a.header.stamp_ns: a.joint_velocities for a in messages(session, ARM_COMMAND)}
    lateral = robot.base.kind == "omnidirectional"
    base = "stamp_s,forward,angular," + ("lateral," if lateral else "")
    lines = [base + ",".join(f"{n}_dot" for n in robot.joint_names)]
    for b in messages(session, BASE_COMMAND):
        joints = arm.get(b.header.stamp_ns)
        if joints is not None:
            side = (b.lateral_velocity,) if lateral else ()
            values = (b.forward_velocity, b.angular_velocity, *side, *joints)
            lines.append(f"{b.header.stamp_ns / 1e9:.3f}," + ",".join(repr(v) for v in values))
    return "\n".join(lines) + "\n"
