"""The vision tracker: ArUco markers in each camera frame, a pose per marker (section 6.1.1).

Input: ``camera/image`` (the simulator's, or a camera component's: raw pixels or JPEG, made
grey), or with ``device`` set a
``cv2.VideoCapture`` (a device index such as ``0``, a URL or a video file) read at the
scene's camera rate, with the intrinsics of the ``calibration`` YAML file (``fx fy cx cy``
and optional ``distortion``).

Output: ``vision/markers``, every scene marker found, its pose in the camera frame, the fit's
reprojection error and its corners in the image (refined to sub-pixel), stamped with the
frame's stamp (an empty list when none is found: ``frames_without_markers`` counts them).
The reference marker F0 is fitted by the square-marker method (``solvePnP`` IPPE; a fit tilted
away from the filtered one, IPPE's other solution, is left out) and low-pass filtered (eq.
6.1): that gives the floor plane, on which F0's own position and yaw are then measured like
the others'.
Every other marker lies flat at a known height above that floor, so its pose comes from the
plane instead: the ray through its centre meets the plane, the yaw comes from its edges.
Before F0 is seen, every marker gets the square fit.
"""

from __future__ import annotations

import logging
from pathlib import Path

import cv2
import numpy as np

from components.params import Param, ParamError
from components.process_entry import run_component
from components.pubsub import Input
from components.runtime import Component, Node
from messages import topics
from messages.camera import CameraFrame
from messages.markers import MarkerDetection, MarkerDetections
from profiles.scene import Scene
from vision.camera_file import CameraFile, read_camera_file
from vision.camera_pose import placement_of
from vision.frame_source import FrameSourceError, ask_size, open_capture
from vision.images import grey
from vision.markers import (
    THRESHOLD_WINDOW_PX,
    Intrinsics,
    MarkerDetector,
    plane_of,
    plane_pose,
    square_pose,
)
from wbc import dq
from wbc.pose_filter import PoseFilter

FLIP_DEG = 3.0
"""A square fit of F0 tilted this far from the filtered one is IPPE's wrong solution."""
FLIP_MIN_SAMPLES = 10
"""Fits filtered before the tilt check applies."""

log = logging.getLogger("components.vision_tracker")


class VisionTracker(Component):
    """camera/image (or a capture device) in, vision/markers out."""

    reads = (Input(topics.CAMERA_IMAGE),)
    writes = (topics.VISION_MARKERS,)
    params = (
        Param("device", str, "", doc="cv2.VideoCapture source; empty: the camera/image topic"),
        Param("calibration", str, "", doc="intrinsics YAML of the capture device"),
        Param(
            "reference_samples",
            int,
            100,
            low=1,
            high=100000,
            doc="eq. 6.1 samples of the floor reference F0",
        ),
        Param("plane_fit", bool, True, doc="fit markers on their known plane (else IPPE only)"),
        Param(
            "threshold_window_px",
            int,
            THRESHOLD_WINDOW_PX,
            low=3,
            high=255,
            doc="the adaptive threshold's window, px (about a marker's side or less)",
        ),
        Param(
            "threads",
            int,
            1,
            low=0,
            high=256,
            doc="OpenCV's worker threads (0: one per core); 1 spends the least CPU per frame",
        ),
    )

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        if node.profile.scene is None:
            raise ParamError("the vision tracker needs the profile's `scene` (markers)")
        self.scene: Scene = node.profile.scene
        self.markers = self.scene.markers()
        cv2.setNumThreads(node.params["threads"] or -1)
        self.detector = MarkerDetector(self.scene.dictionary_id, node.params["threshold_window_px"])
        self.reference = PoseFilter(node.params["reference_samples"])
        self.output = node.publisher(topics.VISION_MARKERS)
        node.counters["frames"] = 0
        node.counters["frames_without_markers"] = 0
        node.counters["unknown_markers"] = 0
        node.counters["reference_flips"] = 0
        node.counters["undecodable_frames"] = 0
        self._placed = False
        self.capture = None
        if node.params["device"]:
            self.capture, self.intrinsics = self._open_device()
            node.timer(1.0 / self.scene.camera.rate_hz, self._read_device)
        else:
            node.subscribe(topics.CAMERA_IMAGE, self.on_frame)

    def on_frame(self, frame: CameraFrame) -> None:
        """One image from the topic: detect, fit, publish. A JPEG that does not decode to the
        frame's size is dropped and counted (``undecodable_frames``)."""
        try:
            image = grey(frame.data, frame.encoding, frame.width, frame.height)
        except ValueError as error:
            self.node.count("undecodable_frames")
            self.node.warn("undecodable_frames", f"dropped frame {frame.header.seq}: {error}")
            return
        i = frame.intrinsics
        intrinsics = Intrinsics(i.fx, i.fy, i.cx, i.cy, tuple(i.distortion))
        self.track(image, intrinsics, frame.header.stamp_ns)

    def track(self, image: np.ndarray, intrinsics: Intrinsics, stamp_ns: int) -> None:
        """Publish the markers of ``image`` with the stamp of the frame."""
        self.node.count("frames")
        found = []
        detections = {d.id: d for d in self.detector.detect(image)}
        reference = detections.get(self.scene.reference.id)
        reference_pose = None
        if reference is not None:
            pose, error = square_pose(reference, self.scene.reference.size_m, intrinsics)
            if self._consistent(pose):
                self.reference.update(pose)
                self._say_where_the_camera_is()
            reference_pose = self.reference.pose
            if self.node.params["plane_fit"]:
                # The floor plane from the filtered fits; F0's position and yaw on it.
                normal, offset = plane_of(reference_pose, 0.0)
                pose, error = plane_pose(
                    reference, self.scene.reference.size_m, intrinsics, normal, offset
                )
            found.append((reference, pose, error))
        elif self.reference.pose is not None:
            reference_pose = self.reference.pose
        for marker_id, detection in detections.items():
            marker = self.markers.get(marker_id)
            if marker is None:
                self.node.count("unknown_markers")
                continue
            if marker_id == self.scene.reference.id:
                continue
            if reference_pose is not None and self.node.params["plane_fit"]:
                height = marker.height_m - self.scene.reference.height_m
                normal, offset = plane_of(reference_pose, height)
                pose, error = plane_pose(detection, marker.size_m, intrinsics, normal, offset)
            else:
                pose, error = square_pose(detection, marker.size_m, intrinsics)
            found.append((detection, pose, error))
        if not found:
            self.node.count("frames_without_markers")
        self.output.put(
            MarkerDetections(
                header=self.node.header("camera", stamp_ns, self.output.next_seq),
                markers=tuple(
                    MarkerDetection(
                        id=d.id,
                        pose=tuple(p.tolist()),
                        reprojection_error=float(e),
                        corners=tuple(map(tuple, d.corners.tolist())),
                    )
                    for d, p, e in sorted(found, key=lambda item: item[0].id)
                ),
            )
        )

    def _consistent(self, pose: np.ndarray) -> bool:
        """False for a square fit of F0 whose face normal is over ``FLIP_DEG`` from the
        filtered one: IPPE's other solution (the two-fold ambiguity of a planar square),
        counted as ``reference_flips`` and left out of the filter."""
        if self.reference.pose is None or self.reference.count < FLIP_MIN_SAMPLES:
            return True
        normal = dq.rotation_matrix(dq.rotation(pose))[:, 2]
        filtered = dq.rotation_matrix(dq.rotation(self.reference.pose))[:, 2]
        if float(np.dot(normal, filtered)) >= np.cos(np.radians(FLIP_DEG)):
            return True
        self.node.count("reference_flips")
        return False

    def _say_where_the_camera_is(self) -> None:
        """Log, once F0's filter holds ``FLIP_MIN_SAMPLES`` fits, the camera's height and tilt
        over the floor (``vision.camera_pose``; `parsimony calibrate ceiling` compares them with
        the profile's camera)."""
        if self._placed or self.reference.count < FLIP_MIN_SAMPLES:
            return
        self._placed = True
        found = placement_of(self.reference.pose, self.scene.reference.height_m)
        log.info("%s", found.describe())

    # -- a real camera ---------------------------------------------------------------------

    def _open_device(self):
        """The capture, asked for the calibration's image size when the file gives one, and
        the calibration's intrinsics."""
        source = str(self.node.params["device"])
        try:
            capture = open_capture(source)
        except FrameSourceError as error:
            raise ParamError(f"device: cannot open {source!r}") from error
        self.calibration = load_calibration(Path(str(self.node.params["calibration"])))
        ask_size(capture, source, self.calibration.size)
        return capture, self.calibration.intrinsics

    def _read_device(self) -> None:
        ok, image = self.capture.read()
        if not ok:
            self.node.count("capture_failures")
            self.node.warn("capture_failures", f"no frame from {self.node.params['device']}")
            return
        if image.ndim == 3:
            image = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
        mismatch = self.calibration.size_mismatch(image.shape[1], image.shape[0])
        if mismatch:
            self.node.warn("calibration_size", mismatch)
        self.track(image, self.intrinsics, self.node.clock.now_ns())

    def shutdown(self) -> None:
        if self.capture is not None:
            self.capture.release()


def load_calibration(path: Path) -> CameraFile:
    """The intrinsics file (``vision.camera_file``): ``fx fy cx cy`` (px), optional
    ``distortion`` and image ``width`` and ``height``; or ``ParamError``."""
    try:
        return read_camera_file(path)
    except (OSError, ValueError) as error:
        raise ParamError(f"calibration: cannot read intrinsics from {path}: {error}") from error


if __name__ == "__main__":
    run_component(VisionTracker)
