"""The simulator's ceiling camera draws the scene's markers where they are (the base's unless
hidden), sends each frame in the format asked for, skips a frame due while the last is drawn in
real time, waits for it in lockstep, and reports a frame it cannot draw instead of dying."""

from __future__ import annotations

import threading
from collections.abc import Iterator

import numpy as np
import pytest

from components.sim_camera import FrameFormat, SimCamera
from messages.camera import CameraFrame
from messages.header import Header
from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from sim2d.camera import ImageNoise
from vision.images import grey
from vision.markers import MarkerDetector
from wbc.geometry.obstacles import Circle
from wbc.robot import MobileManipulator

PROFILE = load_profile(DEPLOY / "sim.yaml")
SCENE = PROFILE.scene
ROBOT = MobileManipulator.from_yaml(PROFILE.robot)
Q = np.array([0.8, 0.15, 0.0])
"""The base under the camera (at (0.8, 0.15), 2.5 m up): every marker is in view."""
MONO8, JPEG = FrameFormat("mono8", 90), FrameFormat("jpeg", 90)


class Frames:
    """What the camera publishes, and how often it failed."""

    def __init__(self) -> None:
        self.sent: list[CameraFrame] = []
        self.errors = 0
        self.gate = threading.Event()
        self.gate.set()

    def publish(self, frame: CameraFrame) -> None:
        self.gate.wait(10.0)
        self.sent.append(frame)

    def failed(self) -> None:
        self.errors += 1


@pytest.fixture
def frames() -> Frames:
    return Frames()


@pytest.fixture
def camera(frames: Frames) -> Iterator[SimCamera]:
    made = SimCamera(
        SCENE,
        ROBOT,
        [Circle(0.3, -0.4, 0.1)],
        [1.2, 0.5, 0.0],
        ImageNoise(0.0, 0.0),
        np.random.default_rng(0),
        frames.publish,
        frames.failed,
    )
    yield made
    frames.gate.set()
    made.shutdown()


def header(seq: int) -> Header:
    return Header(stamp_ns=seq * 33_000_000, frame="camera", seq=seq, source="simulator")


def seen(frame: CameraFrame) -> set[int]:
    return {
        d.id
        for d in MarkerDetector(SCENE.dictionary_id).detect(
            grey(frame.data, frame.encoding, frame.width, frame.height)
        )
    }


def test_a_frame_shows_the_floor_the_bin_the_obstacle_and_the_base(camera, frames) -> None:
    assert camera.take(header(1), Q, False, MONO8, wait=True)
    camera.shutdown()
    (frame,) = frames.sent
    assert (frame.width, frame.height, frame.encoding) == (640, 480, "mono8")
    assert len(frame.data) == 640 * 480
    assert (frame.intrinsics.fx, frame.intrinsics.cx) == (600.0, 319.5)
    assert frame.header == header(1)
    assert seen(frame) == {0, 1, 2, 3}  # reference, base, bin, obstacle


def test_a_hidden_base_marker_is_not_drawn(camera, frames) -> None:
    camera.take(header(1), Q, True, JPEG, wait=True)
    camera.shutdown()
    (frame,) = frames.sent
    assert frame.encoding == "jpeg" and frame.data[:2] == b"\xff\xd8"
    assert seen(frame) == {0, 2, 3}


def test_real_time_skips_a_frame_while_the_last_is_drawn_lockstep_waits(camera, frames) -> None:
    frames.gate.clear()  # the first frame is held in publishing
    assert camera.take(header(1), Q, False, MONO8, wait=False)
    assert not camera.take(header(2), Q, False, MONO8, wait=False)
    frames.gate.set()
    assert camera.take(header(3), Q, False, MONO8, wait=True)
    camera.shutdown()
    assert [f.header.seq for f in frames.sent] == [1, 3]


def test_a_frame_that_cannot_be_sent_is_reported(camera, frames) -> None:
    camera.publish = lambda frame: 1 / 0
    camera.take(header(1), Q, False, MONO8, wait=True)
    camera.take(header(2), Q, False, MONO8, wait=True)
    camera.shutdown()
    assert frames.errors == 2 and frames.sent == []
