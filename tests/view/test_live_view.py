"""`parsimony view` as a user runs it: a real process on a real namespace, watched by a
WebSocket client that speaks Foxglove's protocol (subprotocol ``foxglove.sdk.v1``) as the app
does. It receives the channel advertisements, then live images and frames, each decoded with
the schema the server advertised."""

from __future__ import annotations

import asyncio
import base64
import math
import random
import signal
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import zenoh

from messages import codec, topics
from messages.camera import CameraFrame
from messages.state import RobotState
from profiles.endpoints import free_port
from profiles.profile import load_profile
from record.session_file import CARRIED_FIELD, CARRIER, from_json, schema_of
from scenes.foxglove_views import View
from tests.parsimony.in_process import completed
from tests.scenes.views_read import decode
from tests.view.live_view_client import (
    DEADLINE_S,
    NAMESPACE,
    StderrLines,
    header,
    state,
    watch,
    write_profile,
)

WIDTH, HEIGHT = 64, 48
PERIOD_S = 0.05
"""How often the test's system publishes an image and a state."""
IMAGE_VIEW = f"{NAMESPACE}/camera/image/foxglove"
FRAMES_VIEW = f"{NAMESPACE}/robot/state/foxglove"
STATE_JSON = f"{NAMESPACE}/robot/state"


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
    done = completed("view", str(write_profile(tmp_path)), "--keys", "camera/imag")
    assert done.returncode == 2
    assert "keys: 'camera/imag' matches no topic" in done.stderr
