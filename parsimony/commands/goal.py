"""`parsimony goal X Y Z`: send the robot a goal for its gripper, and follow it with --wait.

The goal is built as a client's goal of the live view is (``view.client_goals``: finite, a
unit quaternion, above the floor, not inside an obstacle nor farther than a plan may cover
from the robot), stamped on the profile's clock (``launch.tool_clock``) and sent the way the
profile takes goals: on ``goal/request`` where a component (the staging supervisor) reads it,
else on ``control/goal``. With --wait it follows ``supervisor/status``
(``launch.goal_follower``), its phases and the goal's error on stderr, until the goal is
reached (exit 0) or ends otherwise: unreachable, refused, aborted (exit 1). Input that cannot
be used exits 2.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import threading

import numpy as np
import zenoh

from launch.goal_follower import GoalFollower, Outcome
from launch.graph import dataflow
from launch.query import QueryError, live_writers, overwritten_by
from launch.tool_clock import ToolClock
from messages import codec, topics
from messages.goal import Goal
from messages.header import Header
from messages.obstacles import circles_of
from messages.state import RobotState
from messages.supervisor import SupervisorStatus
from outputs.stdout import emit, json_text
from parsimony.target_options import fail, profile_and_target, target_options
from profiles.profile import Profile, ProfileError
from view.client_goals import GoalRefused, client_goal
from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.planar import offset_pose, planar_pose

SOURCE = "parsimony"
"""The source named in the goal's header."""
TIMEOUT_S = 10.0
"""How long the command waits for each answer by default: longer than a query's (a loaded
machine's simulation may leave a second between two statuses)."""
FRAMES = ("world", "base")


def finite(text: str) -> float:
    """An argument type: a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `goal` and its arguments."""
    parser = subparsers.add_parser(
        "goal",
        parents=[target_options()],
        conflict_handler="resolve",
        help="send the gripper to a pose (or a position) and follow it",
        description="Send the robot a goal for its gripper, stamped on the profile's clock, "
        "where the profile takes goals: goal/request when a staging supervisor reads it, else "
        "control/goal. Lengths in metres, angles in degrees. Exits 0 (sent, or with --wait "
        "reached), 1 (refused, unreachable, or no answer), 2 (input that cannot be used).",
    )
    for axis in "xyz":
        parser.add_argument(
            axis, type=finite, metavar=axis.upper(), help=f"the gripper's {axis} in the frame, m"
        )
    turn = parser.add_mutually_exclusive_group()
    turn.add_argument(
        "--yaw",
        type=finite,
        metavar="DEG",
        default=0.0,
        help="the gripper level, pointing this many degrees from the frame's x "
        "towards its y (default 0)",
    )
    turn.add_argument(
        "--rpy",
        type=finite,
        nargs=3,
        metavar=("ROLL", "PITCH", "YAW"),
        help="the gripper's roll, pitch and yaw in degrees: the rotation "
        "Rz(yaw) Ry(pitch) Rx(roll) of the frame's axes",
    )
    parser.add_argument(
        "--position",
        action="store_true",
        help="a position goal: the gripper to X Y Z, its orientation free",
    )
    parser.add_argument(
        "--frame",
        choices=FRAMES,
        default="world",
        help="world: F0, where the state is given (default); base: the robot's "
        "base as it stands now, x ahead, y to its left, z up from the "
        "floor",
    )
    parser.add_argument(
        "--wait",
        action="store_true",
        help="follow supervisor/status until the goal is reached or refused, "
        "its phases and the goal's error on stderr",
    )
    parser.add_argument(
        "--timeout",
        type=float,
        default=TIMEOUT_S,
        metavar="S",
        help="seconds to wait for the clock, the robot's state, the "
        f"supervisor's answer and, with --wait, each status (default "
        f"{TIMEOUT_S:g})",
    )
    return parser


def run(args: argparse.Namespace) -> int:
    try:
        if args.position and args.rpy is not None or args.position and args.yaw != 0.0:
            raise ValueError(
                "--position takes no --yaw or --rpy: a position goal leaves the "
                "gripper's orientation free"
            )
        if not (math.isfinite(args.timeout) and args.timeout > 0.0):
            raise ValueError(
                f"--timeout: expected a finite number of seconds > 0, got {args.timeout}"
            )
        profile, target = profile_and_target(args)
        graph = dataflow(profile)
        topic = (
            topics.GOAL_REQUEST
            if graph.readers(topics.GOAL_REQUEST.name)
            else (topics.CONTROL_GOAL)
        )
        supervisor = next(
            (
                name
                for name in graph.readers(topics.GOAL_REQUEST.name)
                if name in graph.writers(topics.SUPERVISOR_STATUS.name)
            ),
            None,
        )
        if args.wait and supervisor is None:
            raise ValueError(
                f"--wait follows {topics.SUPERVISOR_STATUS.name}, and no component "
                f"of {args.profile} writes it"
            )
        with target.open() as session:
            return send(args, session, profile, topic, supervisor)
    except GoalRefused as error:  # a ValueError, but of the goal, not of the input
        print(f"goal refused: {error}", file=sys.stderr)
        return 1
    except (ProfileError, QueryError, LookupError, ValueError) as error:
        return fail(error)


def send(
    args: argparse.Namespace,
    session: zenoh.Session,
    profile: Profile,
    topic: topics.Topic,
    supervisor: str | None,
) -> int:
    """Check the goal against the robot and the obstacles, send it, follow it with --wait."""
    key = topic.key(profile.namespace)
    with ToolClock(session, profile) as clock, Robot(session, profile.namespace) as robot:
        header = clock.header(0, SOURCE, args.timeout)
        q = robot.wait(args.timeout)
        if q is None:
            if args.frame == "base":
                raise QueryError(
                    f"no valid robot state in {args.timeout:g} s: --frame base "
                    "is the base as it stands"
                )
            print(
                f"goal: no valid robot state in {args.timeout:g} s: not checked against "
                "where the robot stands",
                file=sys.stderr,
            )
        goal = build(args, header, q, robot.obstacles())
    writers = live_writers(session, profile, topic.name, args.timeout)
    if writers:
        print(f"warning: {overwritten_by(writers, key)}", file=sys.stderr)
    follower = (
        GoalFollower(session, profile.namespace, supervisor, args.timeout)
        if (args.wait and supervisor is not None)
        else None
    )
    try:
        put(session, key, goal, args.timeout)
        sent = f"sent on {key}: {described(goal)}"
        if follower is None:
            emit(
                json_text({"topic": topic.name, "key": key, "goal": goal.model_dump()})
                if args.json
                else sent
            )
            return 0
        print(f"goal: {sent}", file=sys.stderr)
        follower.sent()
        outcome = follower.follow(Progress(header.stamp_ns), goal.header.stamp_ns)
    finally:
        if follower is not None:
            follower.close()
    return reported(args, topic, key, goal, outcome, header.stamp_ns)


def build(
    args: argparse.Namespace, header: Header, q: np.ndarray | None, obstacles: tuple[Circle, ...]
) -> Goal:
    """The goal the arguments give, checked as a client's goal of the live view is."""
    roll, pitch, yaw = args.rpy if args.rpy is not None else (0.0, 0.0, args.yaw)
    pose = offset_pose(args.x, args.y, args.z, *(math.radians(a) for a in (yaw, pitch, roll)))
    if args.frame == "base":
        assert q is not None
        pose = dq.mul(planar_pose(*q[:3]), pose)
    w, x, y, z = dq.rotation(pose)
    px, py, pz = dq.translation(pose)[1:]
    data = json.dumps(
        {"position": {"x": px, "y": py, "z": pz}, "orientation": {"w": w, "x": x, "y": y, "z": z}}
    ).encode()
    goal = client_goal("foxglove.Pose", data, dq.ONE, header, q, obstacles)
    if args.position:
        return Goal(header=goal.header, task="position", position=(px, py, pz))
    return goal


def put(session: zenoh.Session, key: str, goal: Goal, timeout_s: float) -> None:
    """Publish the goal once a subscriber matches (``QueryError`` if none does)."""
    publisher = session.declare_publisher(key)
    try:
        matched = threading.Event()
        listener = publisher.declare_matching_listener(
            lambda status: matched.set() if status.matching else None
        )
        if not publisher.matching_status.matching and not matched.wait(timeout_s):
            raise QueryError(f"nothing subscribes to {key} (is the system running?)")
        listener.undeclare()
        publisher.put(codec.encode(goal))
    finally:
        publisher.undeclare()


def described(goal: Goal) -> str:
    """Where the goal sends the gripper, in words."""
    if goal.task == "position":
        x, y, z = goal.position
        return f"the gripper to ({x:.3f}, {y:.3f}, {z:.3f}) m in world, any orientation"
    x, y, z = dq.translation(np.array(goal.pose))[1:]
    return f"the gripper to ({x:.3f}, {y:.3f}, {z:.3f}) m in world"


class Progress:
    """Says on stderr each phase and event of the goal as it comes, and the goal's error
    (``SupervisorStatus.error_norm``, where the supervisor gives it), again whenever it has
    halved."""

    def __init__(self, sent_ns: int) -> None:
        self.sent_ns = sent_ns
        self.said: tuple[str, str] | None = None
        self.error_said = math.inf

    def __call__(self, status: SupervisorStatus) -> None:
        error = status.error_norm
        news = (status.phase, status.last_event)
        if news == self.said and not (error is not None and error < self.error_said / 2):
            return
        self.said = news
        self.error_said = error if error is not None else math.inf
        t = (status.header.stamp_ns - self.sent_ns) / 1e9
        words = [f"goal: {t:7.2f} s {status.phase}"]
        words += [status.last_event] if status.last_event not in ("", status.phase) else []
        words += [f"error {error:.4f}"] if error is not None else []
        print(", ".join(words), file=sys.stderr, flush=True)


def reported(
    args: argparse.Namespace,
    topic: topics.Topic,
    key: str,
    goal: Goal,
    outcome: Outcome,
    sent_ns: int,
) -> int:
    """Print how the goal ended: a line (or JSON with --json); 0 if it was reached."""
    status = outcome.status
    took_s = (status.header.stamp_ns - sent_ns) / 1e9 if status is not None else None
    if args.json:
        emit(
            json_text(
                {
                    "topic": topic.name,
                    "key": key,
                    "goal": goal.model_dump(),
                    "result": outcome.result,
                    "reason": outcome.reason,
                    "phase": status.phase if status is not None else None,
                    "took_s": took_s,
                }
            )
        )
    elif outcome.reached:
        emit(f"reached in {took_s:.2f} s: {described(goal)}")
    if not outcome.reached:
        print(f"goal {outcome.result}: {outcome.reason}", file=sys.stderr)
    return 0 if outcome.reached else 1


class Robot:
    """The robot's latest valid state and the obstacles, as they come."""

    def __init__(self, session: zenoh.Session, namespace: str) -> None:
        self._valid = threading.Event()
        self._q: np.ndarray | None = None
        self._obstacles: tuple[Circle, ...] = ()
        self._subscribers = [
            session.declare_subscriber(topics.ROBOT_STATE.key(namespace), self._on_state),
            session.declare_subscriber(topics.WORLD_OBSTACLES.key(namespace), self._on_obstacles),
        ]

    def _on_state(self, sample: zenoh.Sample) -> None:
        try:
            state = codec.decode(sample.payload.to_bytes(), RobotState)
        except codec.DecodeError:
            return
        if state.valid:
            self._q = np.array(state.configuration())
            self._valid.set()

    def _on_obstacles(self, sample: zenoh.Sample) -> None:
        try:
            self._obstacles = circles_of(
                codec.decode(sample.payload.to_bytes(), topics.WORLD_OBSTACLES.type)
            )
        except codec.DecodeError:
            return

    def wait(self, timeout_s: float) -> np.ndarray | None:
        """q = [x, y, phi, q1..q5] of the first valid state within ``timeout_s``, or None."""
        return self._q if self._valid.wait(timeout_s) else None

    def obstacles(self) -> tuple[Circle, ...]:
        return self._obstacles

    def __enter__(self) -> Robot:
        return self

    def __exit__(self, *_: object) -> None:
        for subscriber in self._subscribers:
            subscriber.undeclare()
