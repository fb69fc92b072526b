"""One valid, fully populated message of every wire type (every optional float set)."""

from __future__ import annotations

import math

from messages import (
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
from messages.base import Message
from messages.obstacles import Cylinder, Plane, Solids
from messages.stop import StopState
from messages.supervisor import SupervisorStatus
from messages.teleop import TeleopCommand
from messages.truth import SimTruth

HEADER = Header(stamp_ns=1_700_000_000_123_456_789, frame="world", seq=7, source="test")

QUARTER_TURN_SHIFTED: tuple[float, ...] = (
    math.cos(math.pi / 8),
    0.0,
    0.0,
    math.sin(math.pi / 8),
    # dual part 0.5 * t * r with t = (1, 2, 0.5)
    -0.25 * math.sin(math.pi / 8),
    0.5 * math.cos(math.pi / 8) + 1.0 * math.sin(math.pi / 8),
    1.0 * math.cos(math.pi / 8) - 0.5 * math.sin(math.pi / 8),
    0.25 * math.cos(math.pi / 8),
)
"""A unit dual quaternion: rotation pi/4 about z, then translation (1, 2, 0.5) m."""

SOLIDS = Solids(
    planes=(
        Plane(
            name="table",
            normal=(0.0, 0.0, 1.0),
            offset=0.4,
            footprint=((0.5, -0.4), (1.1, -0.4), (1.1, 0.4), (0.5, 0.4)),
        ),
        Plane(normal=(-1.0, 0.0, 0.0), offset=-2.0),
    ),
    cylinders=(
        Cylinder(name="pole", x=0.2, y=-0.3, radius=0.05, height=0.6),
        Cylinder(x=1.0, y=1.0, radius=0.1),
    ),
)

INTRINSICS = CameraIntrinsics(fx=525.0, fy=524.5, cx=319.5, cy=239.5, distortion=(0.1, -0.2, 0, 0))

IMAGE = CameraFrame(
    header=HEADER,
    encoding="mono8",
    width=640,
    height=480,
    data=bytes(range(256)) * 1200,
    intrinsics=INTRINSICS,
)

STATE = RobotState(
    header=HEADER,
    base_pose=(1.0, 2.0, 0.3),
    arm_joints=(0.1, -0.2, 0.3, -0.4, 0.5),
    end_effector=QUARTER_TURN_SHIFTED,
    valid=True,
    age_s=0.02,
)

POSE_GOAL = Goal(header=HEADER, task="pose", pose=QUARTER_TURN_SHIFTED, eta=5.0, beta=2.0)

POSITION_GOAL = Goal(header=HEADER, task="position", position=(0.5, -0.25, 0.4), eta=1.5, beta=3)

POINT_GOAL = Goal(
    header=HEADER, task="point", point=(0.4, -0.2), arm=(0.0, -0.3, 0.2, 0.0, 0.4), lookahead=0.1
)

HEADING_GOAL = Goal(
    header=HEADER, task="heading", heading=-2.5, point=(0.3, 0.1), arm=(0.0, -0.3, 0.2, 0.0, 0.4)
)

EXAMPLES: tuple[Message, ...] = (
    IMAGE,
    MarkerDetections(
        header=HEADER,
        markers=(MarkerDetection(id=3, pose=QUARTER_TURN_SHIFTED, reprojection_error=0.4),),
    ),
    BaseOdometry(
        header=HEADER,
        left_encoder=-1200,
        right_encoder=65535,
        left_distance=-0.1,
        right_distance=0.2,
        x=1.0,
        y=-2.0,
        phi=3.1,
        forward_velocity=0.2,
        angular_velocity=-0.5,
    ),
    JointStates(header=HEADER, names=("q1", "q2"), positions=(0.1, 0.2), velocities=(0.0, -0.01)),
    STATE,
    Obstacles(header=HEADER, circles=(Circle(x=1.0, y=1.5, radius=0.3),), solids=SOLIDS),
    POSE_GOAL,
    POSITION_GOAL,
    BaseCommand(
        header=HEADER, forward_velocity=0.1, angular_velocity=0.2, left_wheel=0.07, right_wheel=0.13
    ),
    ArmCommand(header=HEADER, joint_velocities=(0.0, 0.1, -0.1, 0.2, -0.2)),
    ControllerDiagnostics(
        header=HEADER,
        law="lp",
        status="optimal",
        reason="",
        objective=0.75,
        nonzero=6,
        practical_nonzero=5,
        active_constraints=("nonholonomic", "error_bound"),
        solve_time_us=310.5,
        error_norm=0.12,
        parameters={"eta": 5.0, "beta": 2.0},
    ),
    ComponentStatus(
        header=HEADER,
        name="lp_controller",
        module="components.lp_controller",
        state="running",
        pid=4242,
        counters={"received": 10, "published": 9},
        parameters={"eta": 5.0, "steps": 3, "law": "lp", "warm_start": True},
        stop=StopState(header=HEADER, stopped=True, reason="a hand in the way"),
    ),
    StopState(header=HEADER, stopped=False),
    TeleopCommand(header=HEADER, forward=0.1, turn=-0.2, joint="q2", joint_velocity=0.3),
    Clock(stamp_ns=123_000_000),
    SimTruth(
        header=HEADER,
        base_pose=(1.0, 2.0, 0.3),
        arm_joints=(0.1, -0.2, 0.3, -0.4, 0.5),
        end_effector=QUARTER_TURN_SHIFTED,
        contacts=2,
        in_contact=False,
        solids=SOLIDS,
        arm_penetrations=1,
        arm_penetrating=True,
    ),
    POINT_GOAL,
    HEADING_GOAL,
    SupervisorStatus(
        header=HEADER,
        phase="turn",
        candidate=2,
        candidate_base=(0.4, -0.1, 3.0),
        plans=2,
        replans=1,
        stalls=1,
        error_norm=0.3,
        last_event="re-plan 1",
        planning_ms=61.5,
    ),
)
