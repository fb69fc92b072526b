"""A synthetic ceiling camera: rendered ArUco markers on a grey floor, seen through a pinhole
camera (``sim2d.pinhole``: p_c = R_c^T (p_w - t_c), u = fx x_c / z_c + cx). A marker on the
plane z_m = 0 of its frame is drawn through the plane homography H = K [r1 r2 t] of its pose
(R, t) in the camera frame, with area antialiasing. A ``Renderer`` draws the elements that do
not move once and each frame only the ones that do (tests/sim2d/test_camera.py prints both
figures).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from sim2d.pinhole import PinholeCamera, read_only
from wbc import dq

FLOOR_GREY = 128.0
"""Grey level of the floor."""
BLACK = 20.0
WHITE = 235.0
"""Grey levels of the printed marker's black and white modules (print and lighting, not 0-255)."""
SUPERSAMPLE = 4
"""Pixels are drawn S x S finer, then area-averaged: black area within 0.1%, centroid 0.01 px."""
QUIET_ZONE_MODULES = 1
"""White margin around the marker's black border, in modules."""
DISC_VERTICES = 96
"""A disc's rim is drawn as the projected polygon of this many points."""
_MIN_DEPTH_M = 1e-3


@dataclass(frozen=True, eq=False)
class PlacedMarker:
    """An ArUco marker of side ``size_m`` (black square incl. its border) placed at ``pose``.

    Marker frame: origin at the centre, z out of the face, x towards the image's right edge,
    y towards its top edge; corners (-s/2, s/2), (s/2, s/2), (s/2, -s/2), (-s/2, -s/2) are
    top-left, top-right, bottom-right, bottom-left (OpenCV's SOLVEPNP_IPPE_SQUARE order).
    """

    id: int
    size_m: float
    pose: np.ndarray

    def __post_init__(self) -> None:
        if self.size_m <= 0.0:
            raise ValueError(f"marker size must be positive, got {self.size_m} m")
        if np.shape(self.pose) != (8,) or not dq.is_unit(np.asarray(self.pose, float)):
            raise ValueError(f"marker pose must be a unit dual quaternion (8,), got {self.pose!r}")
        object.__setattr__(self, "pose", read_only(self.pose))

    def corners_world(self) -> np.ndarray:
        """The corners (top-left, top-right, bottom-right, bottom-left) in the world, (4, 3), m."""
        return _plane_to_world(self.pose, _square(self.size_m))


@dataclass(frozen=True)
class ImageNoise:
    """Sensor model: Gaussian blur of sigma ``blur_sigma_px`` px, then N(0, noise_std^2) grey."""

    noise_std: float = 2.0
    blur_sigma_px: float = 0.6


def _square(side: float) -> np.ndarray:
    h = 0.5 * side
    return np.array([[-h, h], [h, h], [h, -h], [-h, -h]])


def _plane_to_world(pose: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """p_w = R [x, y, 0] + t for points (x, y) of the frame's z = 0 plane."""
    rotation = dq.rotation_matrix(dq.rotation(pose))
    return xy @ rotation[:, :2].T + dq.translation(pose)[1:]


def _marker_image(dictionary: cv2.aruco.Dictionary, marker_id: int, module_px: int) -> np.ndarray:
    """The marker with its quiet zone, grey levels BLACK/WHITE, module_px pixels per module."""
    modules = dictionary.markerSize + 2
    marker = cv2.aruco.generateImageMarker(dictionary, marker_id, modules * module_px)
    margin = QUIET_ZONE_MODULES * module_px
    padded = cv2.copyMakeBorder(marker, *(4 * [margin]), cv2.BORDER_CONSTANT, value=255)
    return np.where(padded > 127, WHITE, BLACK).astype(np.float32)


@dataclass(frozen=True, eq=False)
class Composite:
    """A drawn element over the rows v0:v1 and columns u0:u1 of the image: its coverage a and
    its grey levels already multiplied by it, so that drawing it is I = colour + (1 - a) I."""

    v0: int
    v1: int
    u0: int
    u1: int
    colour: np.ndarray
    alpha: np.ndarray

    def draw(self, image: np.ndarray) -> None:
        patch = image[self.v0 : self.v1, self.u0 : self.u1]
        patch[:] = self.colour + (1.0 - self.alpha) * patch


def _marker_composite(
    camera: PinholeCamera, marker: PlacedMarker, dictionary: cv2.aruco.Dictionary
) -> Composite | None:
    """One marker: M warped by D K [r1 r2 t] A (A: source pixel -> marker plane, D: image pixel
    -> supersampled region pixel), a the warped coverage mask, both area-averaged S x S; None
    when it faces away or falls outside the image."""
    modules = dictionary.markerSize + 2
    quiet_side = marker.size_m * (modules + 2 * QUIET_ZONE_MODULES) / modules
    outline_c = camera.to_camera(_plane_to_world(marker.pose, _square(quiet_side)))
    centre_c = camera.to_camera(dq.translation(marker.pose)[1:])[0]
    rotation_c = dq.rotation_matrix(dq.rotation(camera.pose)).T @ dq.rotation_matrix(
        dq.rotation(marker.pose)
    )
    facing = float(rotation_c[:, 2] @ centre_c) < 0.0
    if not facing or np.any(outline_c[:, 2] < _MIN_DEPTH_M):
        return None
    outline = outline_c[:, :2] / outline_c[:, 2:] * [camera.fx, camera.fy] + [camera.cx, camera.cy]
    u0, v0 = np.maximum(np.floor(outline.min(axis=0)).astype(int), 0)
    u1, v1 = np.minimum(np.ceil(outline.max(axis=0)).astype(int) + 1, (camera.width, camera.height))
    if u0 >= u1 or v0 >= v1:
        return None
    s = SUPERSAMPLE
    side_px = float(np.max(np.linalg.norm(outline - np.roll(outline, 1, axis=0), axis=1)))
    module_px = int(np.clip(math.ceil(s * side_px / (modules + 2)), 4, 64))
    source = _marker_image(dictionary, marker.id, module_px)
    length = source.shape[0]
    step = quiet_side / length
    source_to_plane = np.array(
        [
            [step, 0.0, 0.5 * (step - quiet_side)],
            [0.0, -step, 0.5 * (quiet_side - step)],
            [0.0, 0.0, 1.0],
        ]
    )
    plane_to_camera = np.column_stack((rotation_c[:, 0], rotation_c[:, 1], centre_c))  # [r1 r2 t]
    image_to_region = np.array(
        [[s, 0.0, s * (0.5 - u0) - 0.5], [0.0, s, s * (0.5 - v0) - 0.5], [0.0, 0.0, 1.0]]
    )
    homography = image_to_region @ camera.matrix() @ plane_to_camera @ source_to_plane
    size = (s * (u1 - u0), s * (v1 - v0))
    region = (u1 - u0, v1 - v0)
    warped = cv2.warpPerspective(source, homography, size, flags=cv2.INTER_LINEAR)
    mask = cv2.warpPerspective(np.ones_like(source), homography, size, flags=cv2.INTER_LINEAR)
    colour = cv2.resize(warped, region, interpolation=cv2.INTER_AREA)
    alpha = cv2.resize(mask, region, interpolation=cv2.INTER_AREA)
    return Composite(int(v0), int(v1), int(u0), int(u1), colour, alpha)


Disc = tuple[float, float, float, float, int]
"""A horizontal filled disc: centre x, y, z (m), radius (m), grey level."""


def _disc_composite(camera: PinholeCamera, disc: Disc) -> Composite | None:
    """The horizontal disc {|p - (x, y, z)| <= r, p_z = z}: a the coverage of the projected rim
    polygon, filled S x S finer and area-averaged, colour a g."""
    x, y, z, radius, grey = disc
    angles = np.linspace(0.0, 2.0 * math.pi, DISC_VERTICES, endpoint=False)
    rim = np.column_stack(
        (x + radius * np.cos(angles), y + radius * np.sin(angles), np.full_like(angles, z))
    )
    if np.any(camera.to_camera(rim)[:, 2] < _MIN_DEPTH_M):
        return None
    polygon = camera.project(rim)
    u0, v0 = np.maximum(np.floor(polygon.min(axis=0)).astype(int), 0)
    u1, v1 = np.minimum(np.ceil(polygon.max(axis=0)).astype(int) + 1, (camera.width, camera.height))
    if u0 >= u1 or v0 >= v1:
        return None
    s, shift = SUPERSAMPLE, 4
    supersampled = s * (polygon - [u0, v0] + 0.5) - 0.5
    mask = np.zeros((s * (v1 - v0), s * (u1 - u0)), np.float32)
    vertices = np.rint(supersampled * (1 << shift)).astype(np.int32)
    cv2.fillPoly(mask, [vertices], color=1.0, lineType=cv2.LINE_8, shift=shift)
    alpha = cv2.resize(mask, (u1 - u0, v1 - v0), interpolation=cv2.INTER_AREA)
    return Composite(int(v0), int(v1), int(u0), int(u1), alpha * float(grey), alpha)


Element = PlacedMarker | Disc
"""What a frame shows: markers and horizontal discs, drawn in the order given (far first)."""

NOISE_TABLE_FRAMES = 4
"""The noise table holds this many frames' worth of N(0, 1) samples."""


class Renderer:
    """Frames of one camera: I = clip(G_sigma * (floor, elements) + N(0, std^2)), uint8.

    ``static`` elements (the floor markers, the obstacles) are drawn once: those ``below``
    into the floor, those ``above`` kept as composites; each frame draws the moving elements
    between them. The noise of a frame is a window of a table of N(0, 1) samples drawn once
    from ``rng``, at an offset drawn each frame: every pixel's noise is normal and the windows
    of two frames overlap at random, for 0.3 ms where drawing 307,200 normal samples took 4.8.
    The table is scaled by the noise's std once, and each frame is drawn and blurred in buffers
    kept from frame to frame (a fresh 1.2 MB array is fresh pages to fault in, every frame).
    Rendering the default scene took 9.8 ms a frame from scratch, 0.7 ms this way.
    """

    def __init__(
        self,
        camera: PinholeCamera,
        dictionary: int,
        noise: ImageNoise,
        rng: np.random.Generator,
        below: Sequence[Element] = (),
        above: Sequence[Element] = (),
        table_frames: int = NOISE_TABLE_FRAMES,
    ) -> None:
        self.camera, self.noise, self.rng = camera, noise, rng
        self.dictionary = cv2.aruco.getPredefinedDictionary(dictionary)
        self.floor = np.full((camera.height, camera.width), FLOOR_GREY, np.float32)
        for composite in self._composites(below):
            composite.draw(self.floor)
        self.above = self._composites(above)
        pixels = camera.height * camera.width
        self.table = (
            rng.standard_normal(table_frames * pixels, dtype=np.float32)
            * np.float32(noise.noise_std)
            if noise.noise_std > 0.0
            else None
        )
        self._canvas, self._blurred = np.empty_like(self.floor), np.empty_like(self.floor)

    def _composites(self, elements: Sequence[Element]) -> list[Composite]:
        made = [self._composite(element) for element in elements]
        return [composite for composite in made if composite is not None]

    def _composite(self, element: Element) -> Composite | None:
        if isinstance(element, PlacedMarker):
            return _marker_composite(self.camera, element, self.dictionary)
        return _disc_composite(self.camera, element)

    def frame(self, moving: Sequence[Element] = ()) -> np.ndarray:
        """The image with ``moving`` elements drawn over the floor and under the ones above."""
        image = self._canvas
        np.copyto(image, self.floor)
        for composite in [*self._composites(moving), *self.above]:
            composite.draw(image)
        if self.noise.blur_sigma_px > 0.0:
            image = cv2.GaussianBlur(image, (0, 0), self.noise.blur_sigma_px, dst=self._blurred)
        if self.table is None:
            return cv2.add(image, 0.0, dtype=cv2.CV_8U)
        pixels = image.size
        start = int(self.rng.integers(0, self.table.size - pixels + 1))
        window = self.table[start : start + pixels].reshape(image.shape)
        return cv2.add(image, window, dtype=cv2.CV_8U)


def render(
    camera: PinholeCamera,
    markers: Sequence[PlacedMarker],
    dictionary: int,
    noise: ImageNoise,
    rng: np.random.Generator,
    discs: Sequence[Disc] = (),
) -> np.ndarray:
    """The (height, width) uint8 image I = clip(G_sigma * (floor, discs, markers) + N(0, std^2)).

    ``dictionary`` is an OpenCV predefined dictionary id (``cv2.aruco.DICT_4X4_50``); ``discs``
    are horizontal filled discs (x, y, z, radius, grey), m, drawn under the markers. Markers
    that face away from the camera or fall outside the image are skipped. One frame of a
    ``Renderer`` with every element moving, and a noise table of that one frame.
    """
    return Renderer(camera, dictionary, noise, rng, table_frames=1).frame([*discs, *markers])
