"""What the simulator publishes, on the publishers of its ``writes``: its clock, each step's
sensors once (``components.sim_sensors``: the joint states and odometry where the simulator
publishes them, not where drivers do, and the truth, with the ``contacts`` and
``arm_penetrations`` counters) and the camera frames (``components.sim_camera``), one every
1/``rate_hz`` s of simulated time of the scene's camera; in real time a frame due while the
last is drawn is skipped and counted (``frames_skipped``)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from components.runtime import Node
from components.sim_camera import FrameFormat, SimCamera
from components.sim_sensors import SimSensors
from messages import topics
from messages.obstacles import Circle as TruthCircle
from messages.obstacles import Solids
from profiles.scene import Scene
from sim2d.camera import ImageNoise
from sim2d.world import World
from wbc.geometry.obstacles import Circle
from wbc.geometry.obstacles3d import Solid
from wbc.robot import MobileManipulator


class SimOutputs:
    """The publishers of ``writes`` for ``world`` (of ``robot``, ``obstacles`` and ``solids``,
    in ``scene``), the first frame due at ``now_ns`` (see the module docstring)."""

    def __init__(
        self,
        node: Node,
        writes: Sequence[topics.Topic],
        world: World,
        robot: MobileManipulator,
        scene: Scene,
        obstacles: Sequence[Circle],
        solids: tuple[Solid, ...],
        counts_per_turn: int,
        now_ns: int,
    ) -> None:
        p = node.params
        self.node, self.world = node, world
        self.publishers = {t.name: node.publisher(t) for t in writes}
        self.camera = (
            SimCamera(
                scene,
                robot,
                obstacles,
                p["goal_marker"],
                ImageNoise(p["image_noise"], p["image_blur_px"]),
                np.random.default_rng(p["seed"] + 1),
                self.publishers[topics.CAMERA_IMAGE.name].put,
                self._camera_failed,
            )
            if p["camera"]
            else None
        )
        self.frame_period_ns = round(1e9 / scene.camera.rate_hz)
        self.next_frame_ns = now_ns
        self.sensors = SimSensors(
            world,
            scene,
            tuple(TruthCircle(x=c.x, y=c.y, radius=c.radius) for c in obstacles),
            Solids.of(solids),
            counts_per_turn,
        )
        self.sensors_ns: int | None = None
        node.counters["frames_skipped"] = 0
        node.counters["contacts"] = 0
        node.counters["arm_penetrations"] = 0

    def put(self, topic: topics.Topic, message) -> None:
        self.publishers[topic.name].put(message)

    def header(self, frame: str, topic: topics.Topic, now_ns: int):
        return self.node.header(frame, now_ns, self.publishers[topic.name].next_seq)

    def frame_due(self, now_ns: int) -> bool:
        """A camera frame is due at ``now_ns``."""
        return self.camera is not None and now_ns >= self.next_frame_ns

    def sensors_of(self, now_ns: int) -> None:
        """The joints, odometry and truth of the step of ``now_ns``, once."""
        if self.sensors_ns == now_ns:
            return
        self.sensors_ns = now_ns
        sensors = self.sensors
        if topics.ARM_JOINT_STATES.name in self.publishers:  # not where drivers publish them
            header = self.header("arm", topics.ARM_JOINT_STATES, now_ns)
            self.put(topics.ARM_JOINT_STATES, sensors.joints(header))
        if topics.BASE_ODOMETRY.name in self.publishers:
            header = self.header("odom", topics.BASE_ODOMETRY, now_ns)
            self.put(topics.BASE_ODOMETRY, sensors.odometry(header))
        self.node.counters["contacts"] = self.world.contacts
        self.node.counters["arm_penetrations"] = self.world.arm_penetrations
        header = self.header("world", topics.SIM_TRUTH, now_ns)
        self.put(topics.SIM_TRUTH, sensors.truth(header, self.node.params["goal_marker"]))

    def frame(self, now_ns: int, lockstep: bool) -> None:
        """Hand the camera the frame of ``now_ns`` (in real time skipped, and counted, while
        the last is being drawn); the next is due a frame period later."""
        self.next_frame_ns += self.frame_period_ns
        p, now_s = self.node.params, now_ns / 1e9
        hidden = any(start <= now_s < end for start, end in p["hide_base_marker"])
        taken = self.camera.take(
            self.header("camera", topics.CAMERA_IMAGE, now_ns),
            self.world.q,
            hidden,
            FrameFormat(p["image_format"], p["jpeg_quality"]),
            wait=lockstep,
        )
        if not taken:
            self.node.count("frames_skipped")

    def _camera_failed(self) -> None:
        """On the camera thread, in its ``except`` block: a frame could not be drawn."""
        self.node.count("errors.camera")
        self.node.warn("errors.camera", "drawing a camera frame failed", True)

    def shutdown(self) -> None:
        if self.camera is not None:
            self.camera.shutdown()
