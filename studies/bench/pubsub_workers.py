"""The two processes of ``studies.bench.zenoh_latency``: a publisher and a subscriber.

Each connects to the bench's router as a component does (``ZenohSettings.component_config``,
the profile's ``mode``) and serves requests from a queue: the
publisher sends a ``Phase`` and replies the stamps it sent; the subscriber replies, per
topic, the (stamp, arrival, note) of every message it received since it was last asked.
"""

from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass
from multiprocessing.queues import Queue
from typing import Any

import zenoh

from messages import codec, topics
from messages.base import IDENTITY_POSE
from messages.camera import CameraFrame, CameraIntrinsics
from messages.goal import Goal
from messages.header import Header
from messages.obstacles import Circle, Obstacles
from messages.state import RobotState
from profiles.deploy_files import ROBOT_FILE
from profiles.network import ZenohSettings
from wbc.geometry.scenarios import NEAR_START, REACH_GOAL
from wbc.robot import MobileManipulator

NAMESPACE = "bench"
START = NEAR_START
GOAL_Q = REACH_GOAL
WIDTH, HEIGHT = 640, 480
FLOOD_CIRCLES = 4
"""Circles in each ``world/obstacles`` message of the flood."""
WAIT_S = 15.0
"""How long anything may take before the bench gives up."""


@dataclass(frozen=True)
class Phase:
    """What the publisher sends: ``count`` messages of ``kind`` at ``rate_hz`` (0: at once)."""

    kind: str
    count: int
    rate_hz: float


def message(kind: str, index: int, count: int, image: bytes) -> tuple[topics.Topic, Any]:
    """Message ``index`` of a phase, stamped now; states move from START towards GOAL_Q."""
    header = Header(stamp_ns=time.time_ns(), frame="world", seq=index, source="bench")
    if kind == "image":
        intrinsics = CameraIntrinsics(fx=500.0, fy=500.0, cx=320.0, cy=240.0)
        frame = CameraFrame(
            header=header,
            encoding="mono8",
            width=WIDTH,
            height=HEIGHT,
            data=image,
            intrinsics=intrinsics,
        )
        return topics.CAMERA_IMAGE, frame
    if kind == "obstacles":
        circles = tuple(Circle(x=0.5 + 0.01 * i, y=0.2, radius=0.1) for i in range(FLOOD_CIRCLES))
        return topics.WORLD_OBSTACLES, Obstacles(header=header, circles=circles)
    if kind == "goal":
        pose = tuple(MobileManipulator.from_yaml(ROBOT_FILE).fkm(GOAL_Q).tolist())
        return topics.CONTROL_GOAL, Goal(header=header, task="pose", pose=pose)
    q = START + 0.5 * (index / max(count, 1)) * (GOAL_Q - START)
    state = RobotState(
        header=header,
        base_pose=tuple(q[:3].tolist()),
        arm_joints=tuple(q[3:].tolist()),
        end_effector=IDENTITY_POSE,
        valid=True,
        age_s=0.0,
    )
    return topics.ROBOT_STATE, state


def publisher_main(settings: ZenohSettings, commands: Queue, results: Queue) -> None:
    """Publisher process: run each phase it is sent; reply the stamps sent and the duration."""
    image = os.urandom(WIDTH * HEIGHT)
    with zenoh.open(settings.component_config()) as session:
        publishers: dict[str, zenoh.Publisher] = {}
        results.put("ready")
        while (phase := commands.get()) is not None:
            if phase.kind == "obstacles":
                results.put(flood(session, phase))
                continue
            stamps, start = [], time.perf_counter()
            for index in range(phase.count):
                if phase.rate_hz > 0:
                    time.sleep(max(0.0, start + index / phase.rate_hz - time.perf_counter()))
                topic, payload = message(phase.kind, index, phase.count, image)
                if topic.name not in publishers:
                    publishers[topic.name] = session.declare_publisher(topic.key(NAMESPACE))
                    deadline = time.monotonic() + WAIT_S
                    while not publishers[topic.name].matching_status.matching:
                        if time.monotonic() > deadline:
                            raise RuntimeError(f"nobody subscribes to {topic.name}")
                        time.sleep(0.001)
                    start = time.perf_counter()
                publishers[topic.name].put(codec.encode(payload))
                stamps.append(payload.header.stamp_ns)
            results.put((stamps, time.perf_counter() - start))


def flood(session: zenoh.Session, phase: Phase) -> tuple[list[int], float]:
    """Publish ``phase.count`` obstacle messages, encoded beforehand, as fast as the
    subscribers take them: the publisher blocks rather than drop (``CongestionControl.BLOCK``),
    so the rate measures the slowest subscriber, not the publisher's encoding."""
    messages = [message(phase.kind, index, phase.count, b"")[1] for index in range(phase.count)]
    payloads = [codec.encode(m) for m in messages]
    key = topics.WORLD_OBSTACLES.key(NAMESPACE)
    publisher = session.declare_publisher(key, congestion_control=zenoh.CongestionControl.BLOCK)
    try:
        start = time.perf_counter()
        for payload in payloads:
            publisher.put(payload)
        return [m.header.stamp_ns for m in messages], time.perf_counter() - start
    finally:
        publisher.undeclare()


def subscriber_main(settings: ZenohSettings, commands: Queue, results: Queue) -> None:
    """Subscriber process: note (stamp, arrival, note) per topic; reply and forget on request."""
    received: dict[str, list[tuple[int, int, Any]]] = {}
    lock = threading.Lock()

    def on_sample(sample: zenoh.Sample) -> None:
        try:
            topic = topics.topic_of_key(NAMESPACE, str(sample.key_expr))
        except topics.KeyExpressionError:
            return
        decoded = codec.decode(sample.payload.to_bytes(), topic.type)
        arrival = time.time_ns()
        note = getattr(decoded, "solve_time_us", None), getattr(decoded, "status", None)
        with lock:
            received.setdefault(topic.name, []).append((decoded.header.stamp_ns, arrival, note))

    with zenoh.open(settings.component_config()) as session:
        subscriber = session.declare_subscriber(f"{NAMESPACE}/**", on_sample)
        results.put("ready")
        while (topic_name := commands.get()) is not None:
            with lock:
                results.put(received.pop(topic_name, []))
        subscriber.undeclare()
