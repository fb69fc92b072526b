"""messages.camera: an image's data fills its width, height and channels."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from messages import CameraFrame
from tests.messages.message_examples import IMAGE


@pytest.mark.parametrize(("encoding", "pixel_bytes"), [("mono8", 1), ("bgr8", 3), ("rgb8", 3)])
def test_image_data_must_fill_width_height_channels(encoding: str, pixel_bytes: int) -> None:
    fields = {**IMAGE.model_dump(), "encoding": encoding, "width": 4, "height": 3}
    frame = CameraFrame.model_validate(fields | {"data": bytes(12 * pixel_bytes)})
    assert len(frame.data) == 12 * pixel_bytes
    with pytest.raises(ValidationError, match=f"data has 13 bytes, expected {12 * pixel_bytes}"):
        CameraFrame.model_validate(fields | {"data": bytes(13)})


def test_image_repr_leaves_out_the_pixels() -> None:
    assert len(repr(IMAGE)) < 500
