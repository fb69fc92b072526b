"""Hypothesis strategies for every message type."""

from __future__ import annotations

import math

from hypothesis import strategies as st

from messages import (
    CHANNELS,
    ArmCommand,
    BaseCommand,
    BaseOdometry,
    CameraFrame,
    CameraIntrinsics,
    Circle,
    Clock,
    ComponentStatus,
    ControllerDiagnostics,
    Goal,
    Header,
    JointStates,
    MarkerDetection,
    MarkerDetections,
    Obstacles,
    RobotState,
)
from messages.base import UINT64_MAX, Message

finite = st.floats(allow_nan=False, allow_infinity=False)
non_negative = st.floats(min_value=0.0, allow_nan=False, allow_infinity=False)
positive = st.floats(min_value=1e-300, allow_nan=False, allow_infinity=False)
count = st.integers(min_value=0, max_value=UINT64_MAX)
int64 = st.integers(min_value=-(2**63), max_value=2**63 - 1)
names = st.text(max_size=12)


def vectors(length: int) -> st.SearchStrategy[tuple[float, ...]]:
    return st.tuples(*([finite] * length))


def _product(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, ...]:
    """Hamilton product of quaternions ``[w, x, y, z]``."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@st.composite
def unit_dual_quaternions(draw: st.DrawFn) -> tuple[float, ...]:
    """``r + eps 0.5 t r``: a rotation ``r`` followed by a translation ``t`` (m)."""
    unit = st.floats(min_value=-1.0, max_value=1.0)
    raw = draw(st.tuples(unit, unit, unit, unit).filter(lambda q: math.hypot(*q) > 0.1))
    norm = math.hypot(*raw)
    rotation = tuple(c / norm for c in raw)
    metres = st.floats(min_value=-20.0, max_value=20.0)
    translation = (0.0, *draw(st.tuples(metres, metres, metres)))
    dual = tuple(0.5 * c for c in _product(translation, rotation))
    return (*rotation, *dual)


headers = st.builds(Header, stamp_ns=count, frame=names, seq=count, source=names)


@st.composite
def camera_frames(draw: st.DrawFn) -> CameraFrame:
    encoding = draw(st.sampled_from(sorted(CHANNELS)))
    width, height = draw(st.integers(1, 48)), draw(st.integers(1, 48))
    size = width * height * CHANNELS[encoding]
    intrinsics = st.builds(
        CameraIntrinsics,
        fx=positive,
        fy=positive,
        cx=finite,
        cy=finite,
        distortion=st.lists(finite, max_size=8).map(tuple),
    )
    return CameraFrame(
        header=draw(headers),
        encoding=encoding,
        width=width,
        height=height,
        data=draw(st.binary(min_size=size, max_size=size)),
        intrinsics=draw(intrinsics),
    )


@st.composite
def joint_states(draw: st.DrawFn) -> JointStates:
    joint_names = draw(st.lists(names, unique=True, max_size=8))
    n = len(joint_names)
    return JointStates(
        header=draw(headers),
        names=tuple(joint_names),
        positions=draw(vectors(n)),
        velocities=draw(vectors(n)),
    )


@st.composite
def arm_joints(draw: st.DrawFn) -> dict[str, tuple]:
    """One to fourteen uniquely named joints and a value each: ``joint_names`` and ``values``."""
    joint_names = tuple(draw(st.lists(names, unique=True, min_size=1, max_size=14)))
    return {"joint_names": joint_names, "values": draw(vectors(len(joint_names)))}


@st.composite
def robot_states(draw: st.DrawFn) -> RobotState:
    joints = draw(arm_joints())
    return RobotState(
        header=draw(headers),
        base_pose=draw(vectors(3)),
        arm_joints=joints["values"],
        joint_names=joints["joint_names"],
        end_effector=draw(unit_dual_quaternions()),
        valid=draw(st.booleans()),
        age_s=draw(non_negative),
    )


@st.composite
def arm_commands(draw: st.DrawFn) -> ArmCommand:
    joints = draw(arm_joints())
    return ArmCommand(
        header=draw(headers), joint_velocities=joints["values"], joint_names=joints["joint_names"]
    )


def goals() -> st.SearchStrategy[Goal]:
    gain = st.none() | positive
    pose_goals = st.builds(
        Goal,
        header=headers,
        task=st.just("pose"),
        pose=unit_dual_quaternions(),
        eta=gain,
        beta=gain,
    )
    position_goals = st.builds(
        Goal, header=headers, task=st.just("position"), position=vectors(3), eta=gain, beta=gain
    )
    return pose_goals | position_goals


parameter_values = st.booleans() | int64 | finite | st.text(max_size=8)

MESSAGES: dict[type[Message], st.SearchStrategy[Message]] = {
    CameraFrame: camera_frames(),
    MarkerDetections: st.builds(
        MarkerDetections,
        header=headers,
        markers=st.lists(
            st.builds(
                MarkerDetection,
                id=int64,
                pose=unit_dual_quaternions(),
                reprojection_error=non_negative,
            ),
            max_size=4,
        ).map(tuple),
    ),
    BaseOdometry: st.builds(
        BaseOdometry,
        header=headers,
        left_encoder=int64,
        right_encoder=int64,
        left_distance=finite,
        right_distance=finite,
        x=finite,
        y=finite,
        phi=finite,
        forward_velocity=finite,
        angular_velocity=finite,
    ),
    JointStates: joint_states(),
    RobotState: robot_states(),
    Obstacles: st.builds(
        Obstacles,
        header=headers,
        circles=st.lists(st.builds(Circle, x=finite, y=finite, radius=positive), max_size=4).map(
            tuple
        ),
    ),
    Goal: goals(),
    BaseCommand: st.builds(
        BaseCommand,
        header=headers,
        forward_velocity=finite,
        angular_velocity=finite,
        left_wheel=finite,
        right_wheel=finite,
    ),
    ArmCommand: arm_commands(),
    ControllerDiagnostics: st.builds(
        ControllerDiagnostics,
        header=headers,
        law=names,
        status=names,
        reason=names,
        objective=st.none() | finite,
        nonzero=st.integers(0, 100),
        practical_nonzero=st.integers(0, 100),
        active_constraints=st.lists(names, max_size=4).map(tuple),
        solve_time_us=non_negative,
        error_norm=st.none() | non_negative,
        parameters=st.dictionaries(names, finite, max_size=4),
    ),
    ComponentStatus: st.builds(
        ComponentStatus,
        header=headers,
        name=names,
        module=names,
        state=names,
        pid=st.integers(0, 2**22),
        counters=st.dictionaries(names, count, max_size=4),
        parameters=st.dictionaries(names, parameter_values, max_size=4),
    ),
    Clock: st.builds(Clock, stamp_ns=count),
}
"""A strategy per wire type."""
