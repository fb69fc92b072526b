"""Camera images as bytes and back (vision/images.py): raw pixels or JPEG in, a grey array out,
and a clear error for bytes that are not the frame they claim."""

from __future__ import annotations

import numpy as np
import pytest

from vision.images import grey, jpeg

WIDTH, HEIGHT = 8, 6


def test_raw_pixels_give_their_grey_levels() -> None:
    mono = np.arange(WIDTH * HEIGHT, dtype=np.uint8).reshape(HEIGHT, WIDTH)
    np.testing.assert_array_equal(grey(mono.tobytes(), "mono8", WIDTH, HEIGHT), mono)
    colour = np.zeros((HEIGHT, WIDTH, 3), np.uint8)
    colour[..., 0], colour[..., 1], colour[..., 2] = 30, 60, 90
    assert np.all(grey(colour.tobytes(), "rgb8", WIDTH, HEIGHT) == 60)  # the channels' mean


def test_a_jpeg_decodes_to_grey_near_the_image_it_was_made_from() -> None:
    image = np.tile(np.linspace(0, 255, WIDTH * 2, dtype=np.uint8), (HEIGHT * 2, 1))
    decoded = grey(jpeg(image, 95), "jpeg", WIDTH * 2, HEIGHT * 2)
    assert decoded.shape == image.shape
    assert np.abs(decoded.astype(int) - image).max() <= 8


@pytest.mark.parametrize(
    ("data", "encoding", "message"),
    [
        (bytes(WIDTH * HEIGHT - 1), "mono8", "47 bytes do not fill 8x6 mono8"),
        (bytes(WIDTH * HEIGHT), "yuv422", "unknown encoding 'yuv422'"),
        (b"not a jpeg", "jpeg", "the JPEG data does not decode"),
        (jpeg(np.zeros((4, 4), np.uint8), 90), "jpeg", "the JPEG is 4x4, the frame says 8x6"),
    ],
)
def test_bytes_that_are_not_the_frame_are_refused_saying_why(
    data: bytes, encoding: str, message: str
) -> None:
    with pytest.raises(ValueError, match=message):
        grey(data, encoding, WIDTH, HEIGHT)
