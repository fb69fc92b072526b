"""A ChArUco board seen through a synthetic camera of known intrinsics and distortion.

The board's image (``CharucoBoard.generateImage``, grey levels of print) is warped onto an
ideal pinhole image by the homography of its plane at a pose, H = K [r1 r2 t] A (A: board
pixel -> board plane, m), drawn twice finer and area-averaged; then distorted by ``cv2.remap``
with, for each pixel of the distorted image, the ideal pixel it shows (``undistortPoints``
of the pixel, reprojected by K); then blurred and given N(0, 2^2) noise.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from vision.calibration import Board

SIZE = (640, 480)
K_TRUE = np.array([[610.0, 0.0, 322.0], [0.0, 605.0, 236.0], [0.0, 0.0, 1.0]])
DISTORTION_TRUE = np.array([-0.12, 0.06, 0.0015, -0.001, 0.0])
"""Barrel distortion of a small wide lens: 19 px at the image's corners."""
BOARD = Board()
BOARD_PX_PER_M = 1500.0
"""The board's image: about as fine as it is seen (a 35 mm square is some 53 px at 0.4 m)."""
PAD_PX = 32
"""The ideal image is drawn this far beyond each edge: barrel distortion pulls it in."""
SUPERSAMPLE = 2
BLUR_SIGMA_PX = 0.6
NOISE_STD = 2.0
UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 40, 1e-10)


class BoardCamera:
    """Renders ``board`` seen at poses (R, t: the board frame in the camera's, m; board frame
    at its top-left square corner, x along the squares' rows, y down them, z into it)."""

    def __init__(self, board: Board = BOARD, matrix=K_TRUE, distortion=DISTORTION_TRUE) -> None:
        self.board, self.matrix = board, np.asarray(matrix, float)
        square = round(board.square_m * BOARD_PX_PER_M)  # whole pixels: squares all alike
        margin = square // 4
        x, y = (n * square for n in board.squares)
        image = board.charuco().generateImage((x + 2 * margin, y + 2 * margin), marginSize=margin)
        self.image = np.where(image > 127, 235.0, 20.0).astype(np.float32)
        step = board.square_m / square
        self.board_to_plane = np.array(
            [[step, 0.0, (0.5 - margin) * step], [0.0, step, (0.5 - margin) * step], [0, 0, 1]]
        )
        w, h = SIZE
        u, v = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))
        pixels = np.stack((u.ravel(), v.ravel()), axis=1).reshape(-1, 1, 2)
        ideal = cv2.undistortPoints(
            pixels,
            self.matrix,
            np.asarray(distortion, float),
            P=self.matrix,
            criteria=UNDISTORT_CRITERIA,
        ).reshape(h, w, 2)
        self.map_x = (ideal[..., 0] + PAD_PX).astype(np.float32)
        self.map_y = (ideal[..., 1] + PAD_PX).astype(np.float32)
        s = SUPERSAMPLE
        self.to_canvas = np.array(
            [[s, 0.0, s * (PAD_PX + 0.5) - 0.5], [0.0, s, s * (PAD_PX + 0.5) - 0.5], [0, 0, 1]]
        )

    def frame(self, rotation: np.ndarray, translation: np.ndarray, rng) -> np.ndarray:
        """The grey (480, 640) uint8 image of the board at the pose."""
        plane = np.column_stack((rotation[:, 0], rotation[:, 1], translation))
        homography = self.to_canvas @ self.matrix @ plane @ self.board_to_plane
        w, h = SIZE[0] + 2 * PAD_PX, SIZE[1] + 2 * PAD_PX
        fine = cv2.warpPerspective(
            self.image, homography, (SUPERSAMPLE * w, SUPERSAMPLE * h), borderValue=128.0
        )
        ideal = cv2.resize(fine, (w, h), interpolation=cv2.INTER_AREA)
        image = cv2.remap(ideal, self.map_x, self.map_y, cv2.INTER_LINEAR, borderValue=128.0)
        image = cv2.GaussianBlur(image, (0, 0), BLUR_SIGMA_PX)
        return np.clip(image + rng.normal(0.0, NOISE_STD, image.shape), 0, 255).astype(np.uint8)

    def centred_pose(
        self, tilt_x: float, tilt_y: float, yaw: float, centre: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The pose turning the board by ``tilt_x`` and ``tilt_y`` (rad, about the camera's x
        and y) and ``yaw`` about its normal, its centre at ``centre`` (camera frame, m)."""
        tilt, _ = cv2.Rodrigues(np.array([tilt_x, tilt_y, 0.0]))
        turn, _ = cv2.Rodrigues(np.array([0.0, 0.0, yaw]))
        rotation = tilt @ turn
        middle = 0.5 * self.board.square_m * np.array([*self.board.squares, 0.0])
        return rotation, np.asarray(centre, float) - rotation @ middle


def varied_poses(count: int, seed: int, max_tilt_deg: float = 35.0):
    """Poses tilted up to ``max_tilt_deg`` each way, 0.3 to 0.5 m away, spread over the image."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        tilt_x, tilt_y = np.radians(rng.uniform(-max_tilt_deg, max_tilt_deg, 2))
        depth = rng.uniform(0.3, 0.5)
        x, y = rng.uniform(-0.14, 0.14), rng.uniform(-0.1, 0.1)
        centre = np.array([x * depth / 0.4, y * depth / 0.4, depth])
        yield tilt_x, tilt_y, rng.uniform(-0.4, 0.4), centre


def write_views(folder: Path, poses, camera: BoardCamera | None = None, seed: int = 0) -> Path:
    """The frames of the board at ``poses`` (tilt_x, tilt_y, yaw, centre) as PNG files."""
    camera = camera or BoardCamera()
    rng = np.random.default_rng(seed)
    folder.mkdir(parents=True, exist_ok=True)
    for i, pose in enumerate(poses):
        cv2.imwrite(
            str(folder / f"view{i:03d}.png"), camera.frame(*camera.centred_pose(*pose), rng)
        )
    return folder
