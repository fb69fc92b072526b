"""The frames ``parsimony calibrate`` looks through: a folder of images in name order or a
video file, every ``step``-th up to ``limit``, grey; a source that gives no image is one clear
``FrameSourceError``."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from vision.frame_source import FrameSourceError, frames


def shade(level: int) -> np.ndarray:
    """A colour (BGR) image whose grey is ``level`` everywhere."""
    return np.full((24, 32, 3), level, np.uint8)


def test_a_folder_is_read_in_name_order_every_step_th_up_to_limit(tmp_path: Path) -> None:
    for index, name in enumerate(["b.png", "a.png", "d.PNG", "c.bmp", "e.png"]):
        cv2.imwrite(str(tmp_path / name), shade(10 * (index + 1)))
    (tmp_path / "notes.txt").write_text("not an image")
    taken = list(frames(str(tmp_path), limit=2, step=2))
    assert [name for name, _ in taken] == ["a.png", "c.bmp"]  # a b c d e: a, c (limit 2)
    assert [int(image[0, 0]) for _, image in taken] == [20, 40]
    assert all(image.shape == (24, 32) for _, image in taken)


def test_a_folder_without_images_is_refused(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("not an image")
    with pytest.raises(FrameSourceError, match="no images"):
        list(frames(str(tmp_path), limit=5))


def test_an_image_that_does_not_decode_is_refused_by_name(tmp_path: Path) -> None:
    (tmp_path / "broken.png").write_bytes(b"not a png")
    with pytest.raises(FrameSourceError, match="broken.png: not an image"):
        list(frames(str(tmp_path), limit=5))


def test_a_source_that_does_not_exist_is_refused(tmp_path: Path) -> None:
    with pytest.raises(FrameSourceError, match="no such device, file or folder"):
        list(frames(str(tmp_path / "missing.avi"), limit=5))


def test_a_file_that_is_not_a_video_is_refused(tmp_path: Path) -> None:
    text = tmp_path / "notes.avi"
    text.write_text("not a video")
    with pytest.raises(FrameSourceError, match="notes.avi"):
        list(frames(str(text), limit=5))


def test_a_video_gives_every_step_th_frame_grey(tmp_path: Path) -> None:
    video = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 10.0, (32, 24))
    for level in (0, 50, 100, 150, 200):
        writer.write(shade(level))
    writer.release()
    taken = list(frames(str(video), limit=10, step=2))
    assert [name for name, _ in taken] == ["frame 0", "frame 2", "frame 4"]
    assert [image.shape for _, image in taken] == [(24, 32)] * 3
    assert [round(float(image.mean()) / 50) for _, image in taken] == [0, 2, 4]
