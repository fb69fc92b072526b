"""Grey frames from a camera device, a video file or a folder of images, for the commands that
look through the camera before the system runs (``parsimony calibrate``)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm")


class FrameSourceError(ValueError):
    """The source cannot be opened, or gives no image."""


def _grey(image: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image


def open_capture(source: str) -> cv2.VideoCapture:
    """``cv2.VideoCapture`` of a device index (``0``) or of anything it opens (a video file, a
    URL); ``FrameSourceError`` when it does not open (OpenCV's own warnings about each backend
    it tried are kept back: the error says it)."""
    logging = cv2.utils.logging
    level = logging.getLogLevel()
    logging.setLogLevel(logging.LOG_LEVEL_ERROR)
    try:
        capture = cv2.VideoCapture(int(source) if source.isdigit() else source)
    finally:
        logging.setLogLevel(level)
    if not capture.isOpened():
        capture.release()
        raise FrameSourceError(f"{source}: cannot open it as a camera or a video")
    return capture


def ask_size(capture: cv2.VideoCapture, source: str, size: tuple[int, int] | None) -> None:
    """Ask a device for images of ``size`` (width, height); a file's size is its own."""
    if size is not None and source.isdigit():
        capture.set(cv2.CAP_PROP_FRAME_WIDTH, size[0])
        capture.set(cv2.CAP_PROP_FRAME_HEIGHT, size[1])


def frames(
    source: str, limit: int, step: int = 1, size: tuple[int, int] | None = None
) -> Iterator[tuple[str, np.ndarray]]:
    """(name, grey image) of every ``step``-th frame, at most ``limit`` of them: ``source`` is a
    device index (``0``, asked for images of ``size`` (width, height) when given), a folder of
    images (read in name order; one that does not decode is ``FrameSourceError``) or anything
    ``cv2.VideoCapture`` opens (a video file, a URL)."""
    path = Path(source)
    if path.is_dir():
        files = sorted(p for p in path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
        if not files:
            raise FrameSourceError(f"{source}: no images ({', '.join(IMAGE_SUFFIXES)}) in it")
        for file in files[::step][:limit]:
            image = cv2.imread(str(file), cv2.IMREAD_GRAYSCALE)
            if image is None:
                raise FrameSourceError(f"{file}: not an image OpenCV can read")
            yield file.name, image
        return
    if not source.isdigit() and not path.exists() and "://" not in source:
        raise FrameSourceError(f"{source}: no such device, file or folder")
    capture = open_capture(source)
    try:
        ask_size(capture, source, size)
        taken = read = 0
        while taken < limit:
            ok, image = capture.read()
            if not ok:
                if read == 0:
                    raise FrameSourceError(f"{source}: opened, but gives no frame")
                return
            read += 1
            if (read - 1) % step == 0:
                taken += 1
                yield f"frame {read - 1}", _grey(image)
    finally:
        capture.release()
