"""The state estimator process (real Zenoh, the test as its camera, tracker and drivers): the
base pose it estimates from noisy marker fixes and wheel odometry converges to the truth as the
robot drives, the markers of each frame are placed in the world frame F0 at once, and a stale
input is reported: the state is degraded once the base marker is lost, invalid once the
odometry stops as well."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import pytest
import yaml

from messages import codec, topics
from messages.base import default_joint_names
from messages.clock import Clock
from messages.header import Header
from messages.joints import JointStates
from messages.markers import MarkerDetection, MarkerDetections
from messages.odometry import BaseOdometry
from messages.state import RobotState
from profiles.deploy_files import DEPLOY
from profiles.scene import Scene
from wbc import dq
from wbc.planar import compose, in_frame, planar_of, planar_pose

if TYPE_CHECKING:
    from tests.components.conftest import System

STEP_NS = 20_000_000
FRAME_EVERY = 5
"""A camera frame every 5 steps: 10 Hz."""
CAMERA = dq.pose(dq.rotation_quaternion(math.pi, [1.0, 0.0, 0.0]), np.array([-0.3, 0.4, 2.5]))
"""x_0^c: where the reference marker F0 lies in the camera frame (the camera 2.5 m above it,
looking down)."""
START = (0.5, 0.2, 0.3)
"""The base's true pose in F0 at the start, where its odometry reads (0, 0, 0)."""
NOISE_M, NOISE_RAD = 0.02, 0.02
"""The std of the base marker's measured position and heading."""


def estimator_alone() -> str:
    """deploy/sim.yaml's scene and clock with the state estimator alone."""
    data = yaml.safe_load((DEPLOY / "sim.yaml").read_text())
    data["components"] = [c for c in data["components"] if c["name"] == "state_estimator"]
    return yaml.safe_dump(data, sort_keys=False)


class Sensors:
    """The estimator's inputs, one step at a time: the clock, the joints and the odometry of a
    base driving an arc from ``START``, and every ``FRAME_EVERY`` steps a frame of its markers
    (the base's with noise); each step waits for the state it answers."""

    def __init__(self, system: System) -> None:
        namespace = system.profile.namespace
        self.scene: Scene = system.profile.scene
        router = system.router
        self.clock = router.declare_publisher(topics.SIM_CLOCK.key(namespace))
        self.joints = router.declare_publisher(topics.ARM_JOINT_STATES.key(namespace))
        self.odometry = router.declare_publisher(topics.BASE_ODOMETRY.key(namespace))
        self.markers = router.declare_publisher(topics.VISION_MARKERS.key(namespace))
        self.states = system.inbox(topics.ROBOT_STATE)
        self.placed = system.inbox(topics.WORLD_MARKERS)
        self.rng = np.random.default_rng(7)
        self.k = 0
        deadline = time.monotonic() + 30.0
        publishers = (self.joints, self.odometry, self.markers)
        while not all(p.matching_status.matching for p in publishers):
            assert time.monotonic() < deadline, "the estimator did not subscribe in time"
            time.sleep(0.005)

    def truth(self, k: int) -> tuple[float, float, float]:
        """The base's true pose at step k: 0.1 m/s forward, turning at 0.2 rad/s."""
        t = k * STEP_NS / 1e9
        v, w = 0.1, 0.2
        local = (v / w * math.sin(w * t), v / w * (1.0 - math.cos(w * t)), w * t)
        return compose(START, local)

    def header(self, frame: str) -> Header:
        return Header(stamp_ns=self.k * STEP_NS, frame=frame, seq=self.k, source="test")

    def step(self, odometry: bool = True, frame: bool = True) -> RobotState | None:
        """The next step's inputs; its state (None without odometry)."""
        self.k += 1
        stamp = self.k * STEP_NS
        self.clock.put(codec.encode(Clock(stamp_ns=stamp)))
        if frame and self.k % FRAME_EVERY == 0:
            self.markers.put(codec.encode(self.frame()))
        if not odometry:
            return None
        names = default_joint_names(5)  # Little John's
        zeros = (0.0,) * len(names)
        joints = JointStates(
            header=self.header("arm"), names=names, positions=zeros, velocities=zeros
        )
        self.joints.put(codec.encode(joints))
        x, y, phi = in_frame(*self.truth(self.k), START)
        self.odometry.put(
            codec.encode(
                BaseOdometry(
                    header=self.header("odom"),
                    left_encoder=0,
                    right_encoder=0,
                    left_distance=0.0,
                    right_distance=0.0,
                    x=x,
                    y=y,
                    phi=phi,
                    forward_velocity=0.1,
                    angular_velocity=0.2,
                )
            )
        )
        return self.states.wait_for(lambda s: s.header.stamp_ns == stamp, f"at step {self.k}")

    def base_marker(self) -> np.ndarray:
        """The base marker F1 in F0 as the camera measures it: the truth, offset, with noise."""
        base = self.scene.base
        x, y, phi = compose(self.truth(self.k), (*base.offset, 0.0))
        dx, dy = self.rng.normal(0.0, NOISE_M, 2)
        return planar_pose(x + dx, y + dy, phi + self.rng.normal(0.0, NOISE_RAD), base.height_m)

    def frame(self) -> MarkerDetections:
        """The tracker's markers: F0 and F1, in the camera frame (x_i^c = x_0^c x_i^0)."""
        in_camera = {
            self.scene.reference.id: CAMERA,
            self.scene.base.id: dq.normalize(dq.mul(CAMERA, self.base_marker())),
        }
        return MarkerDetections(
            header=self.header("camera"),
            markers=tuple(
                MarkerDetection(id=i, pose=tuple(p.tolist()), reprojection_error=0.1)
                for i, p in in_camera.items()
            ),
        )


@pytest.fixture
def sensors(deployed: Callable[[str], System]) -> Sensors:
    system = deployed(estimator_alone())
    system.start("state_estimator")
    return Sensors(system)


def test_the_base_pose_from_noisy_marker_fixes_converges_to_the_truth(sensors: Sensors) -> None:
    states = [sensors.step() for _ in range(400)]
    assert not states[0].valid  # no fix yet
    last = states[-1]
    assert last.valid and not last.degraded
    x, y, phi = sensors.truth(sensors.k)
    # One fix is off by NOISE_M (2 cm) in each axis; the estimate, averaged, by far less.
    assert math.hypot(last.base_pose[0] - x, last.base_pose[1] - y) < 0.01
    assert last.base_pose[2] == pytest.approx(phi, abs=0.01)


def test_each_frames_markers_are_placed_in_the_world_frame_with_the_frames_stamp(
    sensors: Sensors,
) -> None:
    for _ in range(FRAME_EVERY):
        sensors.step()
    stamp = sensors.k * STEP_NS
    placed = sensors.placed.wait_for(lambda m: m.header.stamp_ns == stamp, "of the frame")
    poses = {m.id: np.array(m.pose) for m in placed.markers}
    reference, base = sensors.scene.reference.id, sensors.scene.base.id
    np.testing.assert_allclose(poses[reference], dq.normalize(dq.mul(dq.conj(CAMERA), CAMERA)))
    x, y, phi = compose(sensors.truth(sensors.k), (*sensors.scene.base.offset, 0.0))
    seen = planar_of(poses[base])
    assert math.hypot(seen[0] - x, seen[1] - y) < 5 * NOISE_M
    assert seen[2] == pytest.approx(phi, abs=5 * NOISE_RAD)


def test_a_lost_marker_degrades_the_state_and_stopped_odometry_invalidates_it(
    sensors: Sensors,
) -> None:
    for _ in range(50):
        state = sensors.step()
    assert state.valid and not state.degraded
    lost_at = sensors.k * STEP_NS
    timeout_ns = 0.5e9  # marker_timeout_s and odometry_timeout_s, the defaults
    blind = [sensors.step(frame=False) for _ in range(50)]  # 1 s without the base marker
    assert all(s.valid for s in blind)
    degraded = [s.header.stamp_ns - lost_at for s in blind if s.degraded]
    assert degraded and min(degraded) > timeout_ns - FRAME_EVERY * STEP_NS
    assert blind[-1].degraded
    silent_from = sensors.k * STEP_NS
    for _ in range(50):  # 1 s of the clock alone
        sensors.step(odometry=False, frame=False)
    invalid = sensors.states.wait_for(
        lambda s: s.header.stamp_ns > silent_from and not s.valid, "reported invalid"
    )
    assert invalid.header.stamp_ns - silent_from > timeout_ns
