"""The intrinsics file of a camera (vision.camera_file): written and read back, a hand-written
one without a size valid, a wrong one refused saying what is wrong."""

from __future__ import annotations

from pathlib import Path

import pytest

from profiles.deploy_files import DEPLOY
from vision.camera_file import CameraFile, camera_file_text, read_camera_file
from vision.markers import Intrinsics


def test_the_intrinsics_file_round_trips_and_the_hand_written_one_stays_valid(
    tmp_path: Path,
) -> None:
    hand = read_camera_file(DEPLOY / "lab" / "camera.yaml")
    assert hand.size is None and hand.size_mismatch(1280, 720) == ""
    camera = CameraFile(
        Intrinsics(610.5, 605.25, 321.0, 236.5, (-0.12, 0.06, 1e-5, 0, 0)), (640, 480)
    )
    path = tmp_path / "camera.yaml"
    path.write_text(camera_file_text(camera, "from a test\non two lines"))
    assert path.read_text().startswith("# from a test\n# on two lines\nfx: 610.5000\n")
    assert read_camera_file(path) == camera
    assert "its calibration is for 640x480" in camera.size_mismatch(1280, 720)


@pytest.mark.parametrize(
    "text, says",
    [
        ("fx: 600\nfy: 600\ncx: 320\n", "has no cy"),
        ("[1, 2]", "is not a mapping"),
        ("fx: -1\nfy: 600\ncx: 320\ncy: 240\n", "must be positive"),
        ("fx: 600\nfy: 600\ncx: 320\ncy: 240\ndistortion: [0.1, 0.2]\n", "4, 5, 8, 12 or 14"),
        ("fx: 600\nfy: 600\ncx: 320\ncy: 240\nwidth: 640\n", "has no height"),
        ("fx: .nan\nfy: 600\ncx: 320\ncy: 240\n", "fx is nan"),
    ],
)
def test_a_wrong_intrinsics_file_says_what_is_wrong(tmp_path: Path, text: str, says: str) -> None:
    path = tmp_path / "camera.yaml"
    path.write_text(text)
    with pytest.raises(ValueError, match=says):
        read_camera_file(path)
