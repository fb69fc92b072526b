"""The simulator's ceiling camera: the scene's markers as the profile places them, drawn
(``sim2d.camera``) on a thread of its own (OpenCV lets go of the GIL), one frame at a time,
encoded as a JPEG of ``jpeg_quality`` or raw mono8, and published as ``camera/image``.

Under the floor's markers (F0, the bin) the base's top disc and its marker (unless hidden by
``hide_base_marker``) move; over them, the obstacles' top discs and markers. In real time a
frame still being drawn when the next is due is skipped (``frames_skipped``); in lockstep the
next waits for it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np

from components.runtime import Node
from messages.camera import CameraFrame, CameraIntrinsics
from messages.header import Header
from sim2d.camera import ImageNoise, PlacedMarker, Renderer, ceiling_camera
from vision.images import jpeg
from wbc.obstacles import Circle
from wbc.planar import compose, planar_pose
from wbc.robot import MobileManipulator

BASE_GREY, OBSTACLE_GREY = 70, 200
"""The grey levels of the base's and the obstacles' top discs."""


class SimCamera:
    """The camera of the simulator of ``node`` (its profile's scene, its parameters)."""

    def __init__(
        self,
        node: Node,
        robot: MobileManipulator,
        obstacles: Sequence[Circle],
        rng: np.random.Generator,
        publish: Callable[[CameraFrame], None],
    ) -> None:
        self.node, self.robot, self.publish = node, robot, publish
        self.scene = node.profile.scene
        self.renderer = self._renderer(obstacles, rng)
        self.thread = ThreadPoolExecutor(1, "camera")
        self.drawing: Future | None = None

    def _renderer(self, obstacles: Sequence[Circle], rng: np.random.Generator) -> Renderer:
        """The floor markers under the base, the obstacles over it, drawn once."""
        scene, p = self.scene, self.node.params
        reference = planar_pose(*scene.reference_pose, scene.reference.height_m)
        gx, gy, gyaw = p["goal_marker"]
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
        noise = ImageNoise(p["image_noise"], p["image_blur_px"])
        return Renderer(ceiling_camera(scene.camera), scene.dictionary_id, noise, rng, below, above)

    def take(self, header: Header, q: np.ndarray, now_s: float, wait: bool) -> None:
        """Start drawing the frame of ``header`` with the robot at ``q``; with ``wait`` after
        the last one is done, else skipped (counted) while the last is being drawn."""
        if self.drawing is not None and not self.drawing.done() and not wait:
            self.node.count("frames_skipped")  # real time: the last is still being drawn
            return
        if self.drawing is not None:
            self.drawing.result()  # lockstep: answered, so all but returned
        self.drawing = self.thread.submit(self._publish_frame, header, self.moving(q, now_s))

    def moving(self, q: np.ndarray, now_s: float) -> list:
        """What moves in the camera's view: the base's top disc, and its marker unless hidden."""
        scene = self.scene
        elements: list = [(q[0], q[1], scene.base.height_m, self.robot.base.body_radius, BASE_GREY)]
        hidden = any(start <= now_s < end for start, end in self.node.params["hide_base_marker"])
        if not hidden:
            x, y, phi = compose(tuple(q[:3]), (*scene.base.offset, 0.0))
            pose = planar_pose(x, y, phi, scene.base.height_m)
            elements.append(PlacedMarker(scene.base.id, scene.base.size_m, pose))
        return elements

    def _publish_frame(self, header: Header, moving: list) -> None:
        """On the camera thread: draw ``moving`` over the scene, encode, publish."""
        try:
            image = self.renderer.frame(moving)
            c, p = self.scene.camera, self.node.params
            jpeg_file = p["image_format"] == "jpeg"
            data = jpeg(image, p["jpeg_quality"]) if jpeg_file else image.tobytes()
            intrinsics = CameraIntrinsics(fx=c.fx, fy=c.fy, cx=c.cx, cy=c.cy)
            self.publish(
                CameraFrame(
                    header=header,
                    encoding=p["image_format"],
                    width=c.width,
                    height=c.height,
                    data=data,
                    intrinsics=intrinsics,
                )
            )
        except Exception:
            self.node.count("errors.camera")
            self.node.warn("errors.camera", "drawing a camera frame failed", True)

    def shutdown(self) -> None:
        self.thread.shutdown(wait=True)
