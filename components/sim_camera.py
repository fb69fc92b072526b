"""The simulator's ceiling camera: the scene's markers, drawn (``sim2d.camera``) on a thread of
its own (OpenCV lets go of the GIL), one frame at a time, encoded as a JPEG or raw mono8 and
handed to a ``publish`` callable (the simulator's ``camera/image`` publisher).

Under the floor's markers (F0, the bin at ``goal_marker``) the base's top disc and its marker
(unless hidden) move; over them, the obstacles' top discs and markers. In real time a frame
still being drawn when the next is due is skipped (``take`` says so); in lockstep the next
waits for it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from messages.camera import CameraFrame, CameraIntrinsics
from messages.header import Header
from profiles.scene import Scene
from sim2d.camera import ImageNoise, PlacedMarker, Renderer
from sim2d.pinhole import ceiling_camera
from vision.images import jpeg
from wbc.geometry.obstacles import Circle
from wbc.planar import compose, planar_pose
from wbc.robot import MobileManipulator

BASE_GREY, OBSTACLE_GREY = 70, 200
"""The grey levels of the base's and the obstacles' top discs."""


@dataclass(frozen=True)
class FrameFormat:
    """How a frame is sent: ``encoding`` "jpeg" (of ``jpeg_quality``) or "mono8"."""

    encoding: str
    jpeg_quality: int

    def encode(self, image: np.ndarray) -> bytes:
        return jpeg(image, self.jpeg_quality) if self.encoding == "jpeg" else image.tobytes()


class SimCamera:
    """The ceiling camera of ``scene`` over ``robot`` and ``obstacles``, the bin marker at
    ``goal_marker`` ([x, y, yaw] in the world); ``on_error`` is called (on the camera thread,
    in the ``except`` block) when a frame cannot be drawn."""

    def __init__(
        self,
        scene: Scene,
        robot: MobileManipulator,
        obstacles: Sequence[Circle],
        goal_marker: Sequence[float],
        noise: ImageNoise,
        rng: np.random.Generator,
        publish: Callable[[CameraFrame], None],
        on_error: Callable[[], None],
    ) -> None:
        self.scene, self.robot = scene, robot
        self.publish, self.on_error = publish, on_error
        self.renderer = self._renderer(obstacles, goal_marker, noise, rng)
        self.thread = ThreadPoolExecutor(1, "camera")
        self.drawing: Future | None = None

    def _renderer(
        self,
        obstacles: Sequence[Circle],
        goal_marker: Sequence[float],
        noise: ImageNoise,
        rng: np.random.Generator,
    ) -> Renderer:
        """The floor markers under the base, the obstacles over it, drawn once."""
        scene = self.scene
        reference = planar_pose(*scene.reference_pose, scene.reference.height_m)
        gx, gy, gyaw = goal_marker
        below = [
            PlacedMarker(scene.reference.id, scene.reference.size_m, reference),
            PlacedMarker(
                scene.goal.id, scene.goal.size_m, planar_pose(gx, gy, gyaw, scene.goal.height_m)
            ),
        ]
        above: list = [
            (o.x, o.y, scene.obstacles.height_m, o.radius, OBSTACLE_GREY) for o in obstacles
        ]
        for marker_id, circle in zip(scene.obstacles.ids, obstacles, strict=False):
            pose = planar_pose(circle.x, circle.y, 0.0, scene.obstacles.height_m)
            above.append(PlacedMarker(marker_id, scene.obstacles.size_m, pose))
        return Renderer(ceiling_camera(scene.camera), scene.dictionary_id, noise, rng, below, above)

    def take(
        self, header: Header, q: np.ndarray, hidden: bool, frame_format: FrameFormat, wait: bool
    ) -> bool:
        """Start drawing the frame of ``header`` with the robot at ``q`` (its marker
        ``hidden`` or not); with ``wait`` after the last one is done, else skipped while the
        last is being drawn. False when skipped."""
        if self.drawing is not None and not self.drawing.done() and not wait:
            return False  # real time: the last is still being drawn
        if self.drawing is not None:
            self.drawing.result()  # lockstep: answered, so all but returned
        moving = self.moving(q, hidden)
        self.drawing = self.thread.submit(self._publish_frame, header, moving, frame_format)
        return True

    def moving(self, q: np.ndarray, hidden: bool) -> list:
        """What moves in the camera's view: the base's top disc, and its marker unless hidden."""
        scene = self.scene
        elements: list = [(q[0], q[1], scene.base.height_m, self.robot.base.body_radius, BASE_GREY)]
        if not hidden:
            x, y, phi = compose(tuple(q[:3]), (*scene.base.offset, 0.0))
            pose = planar_pose(x, y, phi, scene.base.height_m)
            elements.append(PlacedMarker(scene.base.id, scene.base.size_m, pose))
        return elements

    def _publish_frame(self, header: Header, moving: list, frame_format: FrameFormat) -> None:
        """On the camera thread: draw ``moving`` over the scene, encode, publish."""
        try:
            c = self.scene.camera
            self.publish(
                CameraFrame(
                    header=header,
                    encoding=frame_format.encoding,
                    width=c.width,
                    height=c.height,
                    data=frame_format.encode(self.renderer.frame(moving)),
                    intrinsics=CameraIntrinsics(fx=c.fx, fy=c.fy, cx=c.cx, cy=c.cy),
                )
            )
        except Exception:
            self.on_error()

    def shutdown(self) -> None:
        self.thread.shutdown(wait=True)
