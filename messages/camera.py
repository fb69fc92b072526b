"""Camera images and the intrinsics that come with them."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from messages.base import Finite, Message, Positive
from messages.header import Header

Encoding = Literal["mono8", "bgr8", "rgb8"]

CHANNELS: dict[str, int] = {"mono8": 1, "bgr8": 3, "rgb8": 3}
"""Bytes per pixel of each encoding."""


class CameraIntrinsics(Message):
    """Pinhole intrinsics in pixels and OpenCV distortion coefficients (k1, k2, p1, p2, ...)."""

    fx: Positive
    fy: Positive
    cx: Finite
    cy: Finite
    distortion: tuple[Finite, ...] = ()


class CameraFrame(Message):
    """One image, row-major, ``height`` rows of ``width`` pixels, no padding.

    ``data`` holds ``width * height * CHANNELS[encoding]`` bytes.
    """

    header: Header
    encoding: Encoding
    width: int = Field(gt=0)
    height: int = Field(gt=0)
    data: bytes = Field(repr=False)
    intrinsics: CameraIntrinsics

    @model_validator(mode="after")
    def _data_fills_image(self) -> CameraFrame:
        expected = self.width * self.height * CHANNELS[self.encoding]
        if len(self.data) != expected:
            raise ValueError(
                f"data has {len(self.data)} bytes, expected {expected} "
                f"({self.width}x{self.height} {self.encoding})"
            )
        return self
