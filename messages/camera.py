"""Camera images and the intrinsics that come with them.

A frame is raw pixels (``mono8``, ``bgr8``, ``rgb8``: row-major, no padding) or a compressed
image (``jpeg``: a JPEG file, as a UVC camera's MJPEG stream delivers it), whose decoded size
is ``width`` x ``height``.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from messages.base import Finite, Message, Positive
from messages.header import Header

Encoding = Literal["mono8", "bgr8", "rgb8", "jpeg"]

CHANNELS: dict[str, int] = {"mono8": 1, "bgr8": 3, "rgb8": 3}
"""Bytes per pixel of each raw encoding."""
COMPRESSED: dict[str, bytes] = {"jpeg": b"\xff\xd8\xff"}
"""Each compressed encoding and the bytes its files begin with (JPEG: SOI and a marker)."""


class CameraIntrinsics(Message):
    """Pinhole intrinsics in pixels and OpenCV distortion coefficients (k1, k2, p1, p2, ...)."""

    fx: Positive
    fy: Positive
    cx: Finite
    cy: Finite
    distortion: tuple[Finite, ...] = ()


class CameraFrame(Message):
    """One image of ``height`` rows of ``width`` pixels.

    Raw, ``data`` holds ``width * height * CHANNELS[encoding]`` bytes; compressed, a file that
    begins as ``COMPRESSED[encoding]`` says (its decoder checks the rest).
    """

    header: Header
    encoding: Encoding
    width: int = Field(gt=0)
    height: int = Field(gt=0)
    data: bytes = Field(repr=False)
    intrinsics: CameraIntrinsics

    @model_validator(mode="after")
    def _data_fills_image(self) -> CameraFrame:
        if self.encoding in COMPRESSED:
            if not self.data.startswith(COMPRESSED[self.encoding]):
                raise ValueError(f"data is not a {self.encoding} file")
            return self
        expected = self.width * self.height * CHANNELS[self.encoding]
        if len(self.data) != expected:
            raise ValueError(
                f"data has {len(self.data)} bytes, expected {expected} "
                f"({self.width}x{self.height} {self.encoding})"
            )
        return self
