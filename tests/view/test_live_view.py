"""`parsimony view` as a user runs it: a real process on a real namespace, watched by a
WebSocket client that speaks Foxglove's protocol (subprotocol ``foxglove.sdk.v1``) as the app
does. It receives the channel advertisements, then live images and frames, each decoded with
the schema the server advertised."""

from __future__ import annotations

import asyncio
import base64
import json
import math
import random
import signal
import struct
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
import zenoh
from websockets.asyncio.client import connect
from websockets.typing import Subprotocol

from messages import codec, topics
from messages.camera import CameraFrame
from messages.header import Header
from messages.state import RobotState
from profiles.endpoints import free_port
from profiles.profile import load_profile
from record.session_file import CARRIED_FIELD, CARRIER, from_json, schema_of
from scenes.foxglove_views import View
from tests.scenes.views_read import decode

NAMESPACE = "live"
WIDTH, HEIGHT = 64, 48
PERIOD_S = 0.05
"""How often the test's system publishes an image and a state."""
DEADLINE_S = 60.0
"""Generous limit for anything that waits on a process of a loaded machine."""
FIRST_STAMP_NS = 1_700_000_000_000_000_000
IMAGE_VIEW = f"{NAMESPACE}/camera/image/foxglove"
FRAMES_VIEW = f"{NAMESPACE}/robot/state/foxglove"
STATE_JSON = f"{NAMESPACE}/robot/state"
MESSAGE_DATA = 0x01
"""The opcode of a binary message-data frame: then u32 subscription id, u64 log time."""
UNKNOWN_CHANNEL = "Unknown channel ID: "
"""How the server's status message starts when it refuses a subscription."""
WATCHED_MESSAGES = 30
"""How many messages the client reads before it leaves: while it reads the image, every payload
on its key, the ones that are not messages too, reaches the view's decoder (a key no client
reads is not decoded)."""


def header(seq: int) -> Header:
    return Header(stamp_ns=FIRST_STAMP_NS + seq * 50_000_000, frame="world", seq=seq, source="test")


def image(seq: int) -> CameraFrame:
    return CameraFrame.model_validate(
        {
            "header": header(seq),
            "encoding": "mono8",
            "width": WIDTH,
            "height": HEIGHT,
            "data": random.Random(seq).randbytes(WIDTH * HEIGHT),
            "intrinsics": {"fx": 60.0, "fy": 60.0, "cx": 31.5, "cy": 23.5},
        }
    )


def state(seq: int) -> RobotState:
    return RobotState(
        header=header(seq),
        base_pose=(0.5 + 0.01 * seq, -0.25, 0.3),
        arm_joints=(0.1, -0.2, 0.3, -0.4, 0.5),
        end_effector=(1.0, 0.0, 0.0, 0.0, 0.0, 0.2, 0.1, 0.25),
        valid=True,
        age_s=0.0,
    )


class System:
    """The namespace's router (this test's session) and a thread that publishes, every
    ``PERIOD_S``, an image, a robot state and one payload that is not a message."""

    def __init__(self, router: zenoh.Session) -> None:
        self.router = router
        self.published: dict[int, tuple[CameraFrame, RobotState]] = {}
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._publish)
        self.thread.start()

    def _publish(self) -> None:
        camera = self.router.declare_publisher(topics.CAMERA_IMAGE.key(NAMESPACE))
        robot = self.router.declare_publisher(topics.ROBOT_STATE.key(NAMESPACE))
        seq = 0
        while not self.stop.wait(PERIOD_S):
            frame, robot_state = image(seq), state(seq)
            self.published[frame.header.stamp_ns] = (frame, robot_state)
            camera.put(codec.encode(frame))
            robot.put(codec.encode(robot_state))
            camera.put(b"not a message")
            seq += 1


def write_profile(directory: Path) -> Path:
    """A profile of the namespace, its router on a free loopback port."""
    profile = directory / "live.yaml"
    profile.write_text(
        yaml.safe_dump(
            {
                "namespace": NAMESPACE,
                "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
                "components": [{"name": "x", "module": "scripted_publisher", "role": "tool"}],
            }
        )
    )
    return profile


@pytest.fixture
def system(tmp_path: Path) -> Iterator[tuple[Path, System]]:
    profile = write_profile(tmp_path)
    with zenoh.open(load_profile(profile).zenoh.router_config()) as router:
        running = System(router)
        try:
            yield profile, running
        finally:
            running.stop.set()
            running.thread.join()


class StderrLines:
    """The lines a process writes to stderr, read as they come."""

    def __init__(self, process: subprocess.Popen[str]) -> None:
        self.lines: list[str] = []
        self._changed = threading.Condition()
        self._thread = threading.Thread(target=self._read, args=(process,))
        self._thread.start()

    def _read(self, process: subprocess.Popen[str]) -> None:
        for line in process.stderr:
            with self._changed:
                self.lines.append(line)
                self._changed.notify_all()

    def wait_for(self, text: str) -> str:
        """The first line holding ``text``, waiting for it up to ``DEADLINE_S``."""
        with self._changed:
            found = self._changed.wait_for(
                lambda: next((line for line in self.lines if text in line), None), DEADLINE_S
            )
        assert found, f"no {text!r} on stderr within {DEADLINE_S} s: {self.lines}"
        return found

    def all(self) -> str:
        """Everything, once the process has closed its stderr."""
        self._thread.join(DEADLINE_S)
        return "".join(self.lines)


async def watch(address: str, wanted: set[str]) -> tuple[dict, dict[str, tuple[int, bytes]]]:
    """As the Foxglove app: read serverInfo and the advertisements until the ``wanted``
    channels are there, subscribe to them, read ``WATCHED_MESSAGES`` at least, and return them
    by topic with the first (log time, payload) each sends."""
    async with (
        asyncio.timeout(DEADLINE_S),
        connect(address, subprotocols=[Subprotocol("foxglove.sdk.v1")], max_size=None) as client,
    ):
        assert client.subprotocol == "foxglove.sdk.v1"
        server_info = json.loads(await client.recv())
        assert server_info["op"] == "serverInfo", server_info
        channels: dict[str, dict[str, Any]] = {}
        while not wanted <= set(channels):
            message = json.loads(await client.recv())
            if message["op"] == "advertise":
                channels |= {channel["topic"]: channel for channel in message["channels"]}
        topic_of = dict(enumerate(sorted(wanted), start=1))

        async def subscribe(chosen: dict[int, str]) -> None:
            await client.send(
                json.dumps(
                    {
                        "op": "subscribe",
                        "subscriptions": [
                            {"id": sid, "channelId": channels[topic]["id"]}
                            for sid, topic in chosen.items()
                        ],
                    }
                )
            )

        await subscribe(topic_of)
        first: dict[str, tuple[int, bytes]] = {}
        received = 0
        while set(first) != wanted or received < WATCHED_MESSAGES:
            message = await client.recv()
            if isinstance(message, bytes) and message[0] == MESSAGE_DATA:
                subscription, log_time = struct.unpack_from("<IQ", message, 1)
                first.setdefault(topic_of[subscription], (log_time, message[13:]))
                received += 1
            elif isinstance(message, str) and UNKNOWN_CHANNEL in message:
                # foxglove-sdk 0.30 sends an advertisement before it records the channel as
                # advertised to this client: a subscription that follows at once can be refused.
                unknown = int(json.loads(message)["message"].removeprefix(UNKNOWN_CHANNEL))
                await subscribe(
                    {
                        sid: topic
                        for sid, topic in topic_of.items()
                        if channels[topic]["id"] == unknown
                    }
                )
        return channels, first


def decoded(channel: dict[str, Any], payload: bytes) -> dict[str, Any]:
    """A protobuf message read with nothing but the schema its channel advertised."""
    assert (channel["encoding"], channel["schemaEncoding"]) == ("protobuf", "protobuf")
    schema = base64.b64decode(channel["schema"])
    return decode(View("", channel["schemaName"], "protobuf", schema, "protobuf", payload))


def test_a_websocket_client_sees_live_images_and_frames(system) -> None:
    profile, running = system
    port = free_port()
    command = [sys.executable, "-m", "parsimony.cli", "view", str(profile), "--port", str(port)]
    view = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    stderr = StderrLines(view)
    try:
        address = f"ws://127.0.0.1:{port}"
        assert address in stderr.wait_for(" live at ")
        channels, first = asyncio.run(watch(address, {IMAGE_VIEW, FRAMES_VIEW, STATE_JSON}))
    finally:
        view.send_signal(signal.SIGTERM)
        returncode = view.wait(DEADLINE_S)
    assert returncode == 0, stderr.all()

    camera_json = channels[f"{NAMESPACE}/camera/image"]
    assert (camera_json["schemaName"], camera_json["encoding"]) == ("CameraFrame", "json")
    # The image goes once, in its view: the JSON leaves the pixels out and names the carrier.
    assert camera_json["schema"] == schema_of(CameraFrame, "data").decode()
    assert camera_json["metadata"] == {CARRIED_FIELD: "data", CARRIER: IMAGE_VIEW}
    assert channels[IMAGE_VIEW]["schemaName"] == "foxglove.RawImage"
    assert channels[FRAMES_VIEW]["schemaName"] == "foxglove.FrameTransforms"

    # Each payload is the published message of its log time, which is the message's stamp.
    log_time, payload = first[IMAGE_VIEW]
    frame, _ = running.published[log_time]
    raw_image = decoded(channels[IMAGE_VIEW], payload)
    assert (raw_image["width"], raw_image["height"], raw_image["encoding"]) == (
        WIDTH,
        HEIGHT,
        "mono8",
    )
    assert raw_image["data"] == frame.data
    log_time, payload = first[FRAMES_VIEW]
    _, robot_state = running.published[log_time]
    frames = {t["child_frame_id"]: t for t in decoded(channels[FRAMES_VIEW], payload)["transforms"]}
    assert set(frames) == {"estimate/base", "estimate/end_effector"}
    base = frames["estimate/base"]["translation"]
    assert (base["x"], base["y"]) == robot_state.base_pose[:2]
    assert frames["estimate/base"]["rotation"]["z"] == pytest.approx(math.sin(0.15))
    log_time, payload = first[STATE_JSON]
    assert from_json(payload, RobotState) == running.published[log_time][1]

    # The payloads that are not messages are counted, and reported sparingly, naming the key.
    text = stderr.all()
    warnings = [line for line in text.splitlines() if "malformed sample dropped" in line]
    malformed = int(text.split(" messages shown, ")[1].split(" malformed")[0])
    assert warnings and f"{NAMESPACE}/camera/image" in warnings[0]
    assert len(warnings) < malformed


def test_keys_that_match_no_topic_are_refused(tmp_path: Path) -> None:
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "parsimony.cli",
            "view",
            str(write_profile(tmp_path)),
            "--keys",
            "camera/imag",
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2
    assert "keys: 'camera/imag' matches no topic" in done.stderr
