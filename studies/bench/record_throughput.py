"""The recorder's throughput, for ``studies.bench.recording``: a real ``parsimony record`` fed
as fast as this process can publish, alone or beside camera frames at their rate.

The publishers block rather than drop, so only the recorder can lose a sample (and counts it,
``overflowed.<topic>``). Once its counters account for every message it is stopped with SIGINT
and the file read back (``record.session_reader.info``).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import zenoh
from pydantic import BaseModel

from launch import query
from messages import codec, topics
from messages.base import default_joint_names
from messages.camera import CameraFrame, CameraIntrinsics
from messages.header import Header
from messages.joints import JointStates
from messages.odometry import BaseOdometry
from profiles.network import ZenohSettings
from profiles.profile import Profile
from record.session_file import MESSAGE_ENCODING
from record.session_reader import info
from sim2d.camera import ImageNoise, PlacedMarker, render
from sim2d.pinhole import ceiling_camera
from studies.bench.pubsub_workers import NAMESPACE, WAIT_S, message
from wbc.planar import planar_pose

SMALL = (topics.ARM_JOINT_STATES, topics.BASE_ODOMETRY, topics.ROBOT_STATE)
"""The small messages of the floods, sent in turn."""
FRAMES = 8
"""Distinct rendered camera frames the image load cycles through (noise differs)."""
SETTLE_S = 2.0
"""How long the recorder's counters, or the replay's arrivals, may stay still before we count."""


def progress(text: str) -> None:
    """A line of the bench's progress, on stderr."""
    print(f"[bench] {text}", file=sys.stderr, flush=True)


class Camera:
    """Camera frames of the simulation profile's scene camera (size, intrinsics, rate)."""

    def __init__(self, profile: Profile) -> None:
        scene = profile.scene
        self.settings = scene.camera
        reference = PlacedMarker(
            scene.reference.id, scene.reference.size_m, planar_pose(*scene.reference_pose)
        )
        camera, rng = ceiling_camera(scene.camera), np.random.default_rng(0)
        self.images = [
            render(camera, [reference], scene.dictionary_id, ImageNoise(), rng).tobytes()
            for _ in range(FRAMES)
        ]

    def frame(self, header: Header) -> CameraFrame:
        c = self.settings
        intrinsics = CameraIntrinsics(fx=c.fx, fy=c.fy, cx=c.cx, cy=c.cy)
        image = self.images[header.seq % FRAMES]
        return CameraFrame(
            header=header,
            encoding="mono8",
            width=c.width,
            height=c.height,
            data=image,
            intrinsics=intrinsics,
        )


def small_message(topic: topics.Topic, seq: int) -> BaseModel:
    """A joint state, odometry or robot state message stamped now."""
    if topic is topics.ROBOT_STATE:
        return message("state", seq, seq + 1, b"")[1]
    header = Header(stamp_ns=time.time_ns(), frame="bench", seq=seq, source="bench")
    if topic is topics.ARM_JOINT_STATES:
        return JointStates(
            header=header,
            names=default_joint_names(5),
            positions=(0.1, 0.2, 0.3, 0.4, 0.5),
            velocities=(0.0, 0.01, 0.02, 0.03, 0.04),
        )
    return BaseOdometry(
        header=header,
        left_encoder=seq,
        right_encoder=seq,
        left_distance=0.1,
        right_distance=0.1,
        x=0.5,
        y=0.2,
        phi=0.1,
        forward_velocity=0.1,
        angular_velocity=0.0,
    )


@dataclass
class Sent:
    """What a flood published: messages per topic name, payload bytes, seconds it took."""

    counts: Counter
    payload_bytes: int
    seconds: float
    started: float
    """``time.perf_counter`` at the first message."""


def flood(session: zenoh.Session, seconds: float, camera: Camera | None) -> Sent:
    """Small messages in turn as fast as this process can for ``seconds``, and a camera frame
    whenever one is due at the camera's rate (none without ``camera``)."""
    chosen = [*SMALL, topics.CAMERA_IMAGE] if camera is not None else list(SMALL)
    block = zenoh.CongestionControl.BLOCK
    publishers = {
        t.name: session.declare_publisher(t.key(NAMESPACE), congestion_control=block)
        for t in chosen
    }
    deadline = time.monotonic() + WAIT_S
    while not all(p.matching_status.matching for p in publishers.values()):
        if time.monotonic() > deadline:
            raise RuntimeError("the recorder does not subscribe to what the bench publishes")
        time.sleep(0.01)  # the recorder's subscriptions reach this session
    counts: Counter = Counter()
    payload_bytes, index = 0, 0
    started = next_frame = time.perf_counter()
    while (now := time.perf_counter()) < started + seconds:
        if camera is not None and now >= next_frame:
            seq = counts[topics.CAMERA_IMAGE.name]
            header = Header(stamp_ns=time.time_ns(), frame="camera", seq=seq, source="bench")
            topic, payload = topics.CAMERA_IMAGE, codec.encode(camera.frame(header))
            next_frame += 1.0 / camera.settings.rate_hz
        else:
            topic = SMALL[index % len(SMALL)]
            payload = codec.encode(small_message(topic, counts[topic.name]))
            index += 1
        publishers[topic.name].put(payload)
        counts[topic.name] += 1
        payload_bytes += len(payload)
    seconds = time.perf_counter() - started
    for publisher in publishers.values():
        publisher.undeclare()
    return Sent(counts, payload_bytes, seconds, started)


@contextmanager
def recording(profile: Path, path: Path, router: zenoh.Session) -> Iterator[subprocess.Popen]:
    """``parsimony record PROFILE -o PATH`` running, its recorder alive; stopped at the end by
    SIGINT to its process group (what Ctrl-C does), so the file gets its footer."""
    command = [sys.executable, "-m", "parsimony.cli", "record", str(profile), "-o", str(path)]
    process = subprocess.Popen(command, start_new_session=True)
    try:
        deadline = time.monotonic() + WAIT_S * 2
        while "recorder" not in query.live_components(router, NAMESPACE, 0.2):
            if process.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"parsimony record did not come up (exit {process.poll()})")
        yield process
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGINT)
        try:
            process.wait(WAIT_S * 2)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()


def handled(counters: Mapping[str, int]) -> int:
    """Messages the recorder is done with: written, or dropped and counted."""
    dropped = ("overflowed.", "rejected.", "errors.")
    return counters.get("written", 0) + sum(v for k, v in counters.items() if k.startswith(dropped))


def wait_recorded(router: zenoh.Session, sent: Sent) -> tuple[float, dict[str, int]]:
    """Seconds from the first message sent until the recorder had handled every one (or its
    counters last moved, when some never come), and its counters then."""
    total, last, done_s = sum(sent.counts.values()), -1, 0.0
    still_since = time.monotonic()
    while True:
        status = query.statuses(router, NAMESPACE).get("recorder")
        counters = dict(status.counters) if status is not None else {}
        now = handled(counters)
        if now != last:
            last, done_s, still_since = now, time.perf_counter() - sent.started, time.monotonic()
        if now >= total or time.monotonic() - still_since > SETTLE_S:
            return done_s, counters
        time.sleep(0.05)  # polling the recorder's counters, not waiting for an event


def record_throughput(
    name: str,
    camera: Camera | None,
    flood_s: float,
    profile: Path,
    zenoh_settings: ZenohSettings,
    router: zenoh.Session,
    directory: Path,
) -> tuple[dict, dict[str, int]]:
    """One flood of ``flood_s`` seconds into a real recorder: the row of the table and the
    recorder's counters."""
    path = directory / f"{name.split()[0]}.mcap"
    progress(f"record: {name} for {flood_s:g} s")
    with recording(profile, path, router) as process:
        with zenoh.open(zenoh_settings.component_config()) as session:
            sent = flood(session, flood_s, camera)
            done_s, counters = wait_recorded(router, sent)  # closing sooner drops what is queued
    shown = info(path)
    recorded = sum(c["messages"] for c in shown["channels"] if c["encoding"] == MESSAGE_ENCODING)
    total = sum(sent.counts.values())
    row = {
        "load": name,
        "sent": total,
        "sent_hz": round(total / sent.seconds),
        "recorded": recorded,
        "lost": total - recorded,
        "overflowed": sum(v for k, v in counters.items() if k.startswith("overflowed.")),
        "recorded_hz": round(recorded / done_s),
        "file_MBps": round(shown["bytes"] / done_s / 1e6, 1),
        "payload_MBps": round(sent.payload_bytes / done_s / 1e6, 1),
        "file_MB": round(shown["bytes"] / 1e6, 1),
        "drain_s": round(done_s - sent.seconds, 2),
        "exit": process.returncode,
        "complete": shown["complete"],
    }
    return row, {k: v for k, v in sorted(counters.items()) if v}
