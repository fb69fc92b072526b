"""`parsimony calibrate camera` on folders of rendered views of a ChArUco board seen through a
camera of known intrinsics and distortion (tests/vision/board_views.py): it recovers them and
writes the file the vision tracker reads; it refuses too few views, views too alike, frames
without the board and a source it cannot read, each with its reason. `parsimony calibrate
ceiling` on frames of the synthetic ceiling camera, level and tilted."""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from components.vision_tracker import load_calibration
from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from sim2d.camera import ImageNoise, PlacedMarker, render
from sim2d.pinhole import PinholeCamera, ceiling_pose
from tests.parsimony.in_process import run_in_process
from tests.vision.board_views import DISTORTION_TRUE, K_TRUE, SIZE, varied_poses, write_views
from vision.calibration import Board, BoardDetector
from wbc import dq
from wbc.planar import planar_pose

VIEWS = 24
SIM_PROFILE = DEPLOY / "sim.yaml"
CEILING_FRAMES = 8
INTRINSICS_TOLERANCE = 0.005
"""fx, fy, cx, cy within 0.5 % of the truth."""
DISTORTION_TOLERANCE_PX = (1.0, 0.5)
"""The recovered distortion moves every point of the image within 1 px of where the true one
does (it moves them up to 19 px), and every point of the image inset by 5 % within 0.5 px."""


@pytest.fixture(scope="module")
def views(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_views(tmp_path_factory.mktemp("views"), varied_poses(VIEWS, seed=3))


def calibrate(argv: list[str], capsys) -> tuple[int, str, str]:
    return run_in_process(["calibrate", "camera", *argv], capsys)


def distortion_error_px(distortion: list[float], inset: float) -> tuple[float, float]:
    """How far the recovered distortion puts the points of the image from where the true one
    does (both through the true K), px: the largest over a 33 x 25 grid of the image inset by
    ``inset`` of its width and height each side, and the true distortion's largest there."""
    w, h = SIZE
    u, v = np.meshgrid(
        np.linspace(inset * w, (1 - inset) * w - 1, 33),
        np.linspace(inset * h, (1 - inset) * h - 1, 25),
    )
    pixels = np.stack((u.ravel(), v.ravel()), axis=1).reshape(-1, 1, 2)
    rays = cv2.undistortPoints(pixels, K_TRUE, DISTORTION_TRUE).reshape(-1, 2)
    points = np.column_stack((rays, np.ones(len(rays))))
    imaged, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3), K_TRUE, np.array(distortion))
    ideal, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3), K_TRUE, np.zeros(5))
    error = np.linalg.norm(imaged.reshape(-1, 2) - pixels.reshape(-1, 2), axis=1).max()
    size = np.linalg.norm(ideal.reshape(-1, 2) - pixels.reshape(-1, 2), axis=1).max()
    return float(error), float(size)


def test_the_intrinsics_and_distortion_are_recovered_and_written(
    views: Path, tmp_path: Path, capsys
) -> None:
    output = tmp_path / "camera.yaml"
    code, out, err = calibrate([str(views), "-o", str(output), "--json"], capsys)
    assert code == 0, err
    found = json.loads(out)
    truth = {"fx": K_TRUE[0, 0], "fy": K_TRUE[1, 1], "cx": K_TRUE[0, 2], "cy": K_TRUE[1, 2]}
    errors = {k: found[k] / truth[k] - 1.0 for k in truth}
    whole, true_whole = distortion_error_px(found["distortion"], 0.0)
    inner, _ = distortion_error_px(found["distortion"], 0.05)
    print(
        f"views {found['views']}, RMS {found['rms_px']:.3f} px; relative errors "
        + ", ".join(f"{k} {100 * e:+.3f} %" for k, e in errors.items())
        + f"; distortion {np.round(found['distortion'], 5).tolist()} (true "
        f"{DISTORTION_TRUE.tolist()}): points within {whole:.2f} px of the true distortion's "
        f"(of up to {true_whole:.1f} px), {inner:.2f} px inside a 5 % margin"
    )
    assert all(abs(e) < INTRINSICS_TOLERANCE for e in errors.values()), errors
    assert whole < DISTORTION_TOLERANCE_PX[0] and inner < DISTORTION_TOLERANCE_PX[1]
    assert found["distortion"][0] == pytest.approx(DISTORTION_TRUE[0], abs=0.01)
    assert found["views"] == VIEWS and found["rms_px"] < 0.2
    worst = [view["rms_px"] for view in found["worst_views"]]
    assert len(worst) == 3 and worst == sorted(worst, reverse=True) and worst[0] >= found["rms_px"]
    assert (found["width"], found["height"]) == SIZE
    written = load_calibration(output)
    assert written.size == SIZE
    assert written.intrinsics.fx == pytest.approx(found["fx"], abs=1e-4)
    assert written.intrinsics.distortion == pytest.approx(found["distortion"], rel=1e-5)
    assert "corners" in err  # progress on stderr


def test_an_existing_file_is_kept_without_force(views: Path, tmp_path: Path, capsys) -> None:
    output = tmp_path / "camera.yaml"
    output.write_text("fx: 1\n")
    code, _, err = calibrate([str(views), "-o", str(output)], capsys)
    assert code == 2 and "--force" in err
    assert output.read_text() == "fx: 1\n"


def test_too_few_views_are_refused(views: Path, tmp_path: Path, capsys) -> None:
    few = tmp_path / "few"
    few.mkdir()
    for image in sorted(views.iterdir())[:6]:
        (few / image.name).write_bytes(image.read_bytes())
    code, _, err = calibrate([str(few), "-o", str(tmp_path / "c.yaml")], capsys)
    assert code == 1
    assert "refused: too few views: 6 show the board" in err and "10 are needed" in err
    assert not (tmp_path / "c.yaml").exists()


def test_views_of_the_board_held_parallel_to_the_image_are_refused(tmp_path: Path, capsys) -> None:
    """Spread over the image but never tilted: the focal length is not determined."""
    flat = [
        (0.0, 0.0, 0.1 * i, np.array([x, y, 0.4]))
        for i, (x, y) in enumerate(
            [(-0.12, -0.08), (0.12, -0.08), (-0.12, 0.08), (0.12, 0.08), (0.0, 0.0)] * 2
        )
    ]
    folder = write_views(tmp_path / "flat", flat)
    code, _, err = calibrate([str(folder), "-o", str(tmp_path / "c.yaml")], capsys)
    assert code == 1
    assert "refused: views too alike: the board's orientations differ by" in err


def test_frames_without_the_board_are_refused(tmp_path: Path, capsys) -> None:
    folder = tmp_path / "blank"
    folder.mkdir()
    for i in range(3):
        cv2.imwrite(str(folder / f"{i}.png"), np.full((SIZE[1], SIZE[0]), 128, np.uint8))
    code, _, err = calibrate([str(folder), "-o", str(tmp_path / "c.yaml")], capsys)
    assert code == 1
    assert "refused: no board (7x5 squares of 35 mm" in err and "in the 3 frames read" in err


@pytest.mark.parametrize(
    "source, says",
    [
        ("missing", "no such device, file or folder"),
        ("empty", "no images"),
        ("broken", "not an image OpenCV can read"),
        ("text.avi", "cannot open it as a camera or a video"),
        ("99", "99: cannot open it as a camera or a video"),  # no device 99
    ],
)
def test_a_source_that_cannot_be_read_is_one_line(
    tmp_path: Path, capsys, source: str, says: str
) -> None:
    (tmp_path / "empty").mkdir()
    (tmp_path / "broken").mkdir()
    (tmp_path / "broken" / "0.png").write_bytes(b"not a png")
    (tmp_path / "text.avi").write_text("not a video")
    given = source if source.isdigit() else str(tmp_path / source)
    code, _, err = calibrate([given, "-o", str(tmp_path / "c.yaml")], capsys)
    assert code == 2
    assert says in err and len(err.strip().splitlines()) == 1


def test_a_board_that_cannot_be_is_refused_before_reading(tmp_path: Path, capsys) -> None:
    argv = [str(tmp_path), "-o", str(tmp_path / "c.yaml"), "--marker", "0.05"]
    code, _, err = calibrate(argv, capsys)
    assert code == 2 and "must be smaller than the square" in err


def ceiling_frames(folder: Path, tilt_deg: float) -> Path:
    """Frames of deploy/sim.yaml's reference marker from its ceiling camera, turned by
    ``tilt_deg`` about the camera's x axis."""
    scene = load_profile(SIM_PROFILE).scene
    x0, y0, yaw0 = scene.reference_pose
    reference = PlacedMarker(
        scene.reference.id, scene.reference.size_m, planar_pose(x0, y0, yaw0, 0.0)
    )
    tilt = dq.pose(dq.rotation_quaternion(math.radians(tilt_deg), [1.0, 0.0, 0.0]), [0, 0, 0])
    camera = PinholeCamera(dq.mul(ceiling_pose(*scene.camera.position), tilt))
    folder.mkdir()
    for seed in range(CEILING_FRAMES):
        rng = np.random.default_rng(seed)
        image = render(camera, [reference], scene.dictionary_id, ImageNoise(), rng)
        cv2.imwrite(str(folder / f"{seed}.png"), image)
    return folder


@pytest.mark.parametrize("tilt_deg", [0.0, 4.0])
def test_the_ceiling_camera_s_height_and_tilt_over_the_floor(
    tmp_path: Path, capsys, tilt_deg: float
) -> None:
    """deploy/sim.yaml's camera, 2.5 m over the floor, level or tilted: its height within 2 cm
    and its tilt within half a degree; tilted, the floor it sees is off from the profile's
    level camera's, which is said, with the position to declare."""
    folder = ceiling_frames(tmp_path / "frames", tilt_deg)
    argv = ["calibrate", "ceiling", str(SIM_PROFILE), "--source", str(folder), "--json"]
    code, out, err = run_in_process(argv, capsys)
    assert code == 0, err
    found = json.loads(out)
    print(
        f"tilt {tilt_deg}: height {found['height_m']:.4f} m, tilt {found['tilt_deg']:.2f} deg, "
        f"seen floor off by {found['seen_floor_shift_m']:.3f} m"
    )
    assert found["height_m"] == pytest.approx(2.5, abs=0.02)
    assert found["tilt_deg"] == pytest.approx(tilt_deg, abs=0.5)
    assert found["reference_seen"] == CEILING_FRAMES
    if tilt_deg == 0.0:
        assert found["warnings"] == []
    else:
        assert "sight region the supervisor keeps the base in is off" in err
        assert found["warnings"] and "and level the camera" in found["warnings"][0]


def test_a_ceiling_without_the_reference_marker_is_refused(tmp_path: Path, capsys) -> None:
    folder = tmp_path / "blank"
    folder.mkdir()
    cv2.imwrite(str(folder / "0.png"), np.full((480, 640), 128, np.uint8))
    argv = ["calibrate", "ceiling", str(SIM_PROFILE), "--source", str(folder)]
    code, _, err = run_in_process(argv, capsys)
    assert code == 1
    assert "refused: the reference marker (id 0, DICT_4X4_50) is in none of the 1 frames" in err


def test_the_board_to_print_is_the_board_calibration_looks_for(tmp_path: Path, capsys) -> None:
    output = tmp_path / "board.png"
    code, _, err = run_in_process(["calibrate", "board", "-o", str(output), "--dpi", "100"], capsys)
    assert code == 0, err
    assert "its squares cover 245 x 175 mm" in err
    image = cv2.imread(str(output), cv2.IMREAD_GRAYSCALE)
    # 245 x 175 mm and 10 mm of white each side, at 100 dots per inch, to a dot or two.
    assert np.allclose(image.shape, np.array([195, 265]) / 25.4 * 100, atol=2)
    view = BoardDetector(Board()).detect("printed", image)
    assert view is not None and len(view.image_points) == 6 * 4


def test_a_video_of_the_board_calibrates_as_its_frames_do(
    views: Path, tmp_path: Path, capsys
) -> None:
    """The same views as an MJPG video, read through ``cv2.VideoCapture``, every frame."""
    video = tmp_path / "board.avi"
    fourcc = cv2.VideoWriter_fourcc(*"MJPG")
    writer = cv2.VideoWriter(str(video), fourcc, 30.0, SIZE, isColor=False)
    for image in sorted(views.iterdir()):
        writer.write(cv2.imread(str(image), cv2.IMREAD_GRAYSCALE))
    writer.release()
    argv = [str(video), "-o", str(tmp_path / "camera.yaml"), "--json"]
    code, out, err = calibrate(argv, capsys)
    assert code == 0, err
    found = json.loads(out)
    assert found["frames"] == found["views"] == VIEWS
    assert found["fx"] == pytest.approx(K_TRUE[0, 0], rel=INTRINSICS_TOLERANCE)
    assert found["cy"] == pytest.approx(K_TRUE[1, 2], rel=INTRINSICS_TOLERANCE)
