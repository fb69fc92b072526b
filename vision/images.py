"""Camera images as bytes and back: raw pixels or JPEG in, a grey (H, W) uint8 array out.

A colour pixel's grey level is the mean of its three channels; a JPEG is decoded to grey by
libjpeg (OpenCV's ``imdecode``), whatever its channels.
"""

from __future__ import annotations

import cv2
import numpy as np

from messages.camera import CHANNELS


def grey(data: bytes, encoding: str, width: int, height: int) -> np.ndarray:
    """The grey (height, width) image of a frame's bytes, or ``ValueError`` when they do not
    decode to an image of that size."""
    if encoding == "jpeg":
        image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_GRAYSCALE)
        if image is None:
            raise ValueError("the JPEG data does not decode")
        if image.shape != (height, width):
            raise ValueError(
                f"the JPEG is {image.shape[1]}x{image.shape[0]}, the frame says {width}x{height}"
            )
        return image
    channels = CHANNELS.get(encoding)
    if channels is None:
        raise ValueError(f"unknown encoding {encoding!r}")
    if len(data) != width * height * channels:
        raise ValueError(f"{len(data)} bytes do not fill {width}x{height} {encoding}")
    image = np.frombuffer(data, np.uint8).reshape(height, width, channels)
    return image[:, :, 0] if channels == 1 else image.mean(axis=2).astype(np.uint8)


def jpeg(image: np.ndarray, quality: int) -> bytes:
    """A grey or BGR image as a baseline JPEG file of ``quality`` (1..100)."""
    ok, encoded = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:
        raise ValueError("OpenCV could not encode the image as JPEG")
    return encoded.tobytes()
