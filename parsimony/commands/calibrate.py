"""`parsimony calibrate board -o PNG`: a ChArUco board to print. `parsimony calibrate camera
SOURCE -o FILE`: the ceiling camera's intrinsics from views of it (vision.calibration), written
as the vision tracker's intrinsics file (vision.camera_file). `parsimony calibrate ceiling
PROFILE`: where that camera hangs over the floor, from the profile's reference marker
(vision.camera_pose).

SOURCE is a camera device index (``0``), a video file or a folder of images. Exit 1 when the
views cannot determine the intrinsics (the reason names the rule), 2 when the source or the
board cannot be read."""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path

import cv2

from outputs.files import writable_output, written_whole
from outputs.stdout import emit, json_text
from profiles.profile import Profile, ProfileError, load_profile
from sim2d.pinhole import ceiling_camera
from vision.calibration import (
    Board,
    BoardDetector,
    Calibration,
    CalibrationRefused,
    View,
    calibrate,
    evenly,
)
from vision.camera_file import CameraFile, camera_file_text, read_camera_file
from vision.camera_pose import measured_camera, placement, shift_of_seen_floor
from vision.frame_source import FrameSourceError, frames
from vision.markers import Intrinsics, MarkerDetector
from wbc import dq

DEVICE_FRAMES = 300
"""Frames read from a device unless ``--frames`` says otherwise (10 s at 30 Hz)."""
SEEN_FLOOR_TOLERANCE_M = 0.05
"""How far the floor the profile's level camera sees may lie from the one the real camera sees
before a warning: the supervisor keeps the base's axle a margin inside it (0.17 m on Little
John: the marker's offset and half diagonal), and 5 cm spends under a third of that."""
PRINT_MARGIN_M = 0.01
"""White around the printed board's squares."""
LEVEL_DEG = 1.0
"""A tilt the warning asks to level the camera from (the profile's camera can only be level)."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "calibrate", help="calibrate the ceiling camera", description=__doc__
    )
    steps = parser.add_subparsers(dest="what", required=True)
    camera = steps.add_parser(
        "camera",
        help="intrinsics from views of a ChArUco board",
        description="Show the board flat and tilted 20 to 45 degrees each way, near the middle "
        "and near every edge and corner of the image; 20 to 40 views are plenty.",
    )
    camera.add_argument("source", help="device index (0), video file or folder of images")
    camera.add_argument("-o", "--output", type=Path, required=True, help="intrinsics file")
    camera.add_argument("--force", action="store_true", help="write over an existing file")
    _board_arguments(camera)
    camera.add_argument(
        "--frames", type=_positive, help=f"read at most this many (a device: {DEVICE_FRAMES})"
    )
    camera.add_argument("--step", type=_positive, default=1, help="use every STEP-th frame")
    camera.add_argument(
        "--size",
        type=_positive,
        nargs=2,
        metavar=("WIDTH", "HEIGHT"),
        help="ask a device for images of this size (calibrate at the size the tracker will use)",
    )
    camera.add_argument(
        "--max-views",
        type=_positive,
        default=40,
        help="calibrate on at most this many, evenly spread",
    )
    camera.add_argument("--k3", action="store_true", help="fit k3 too (wide-angle lenses)")
    camera.add_argument("--json", action="store_true", help="print the result as JSON")
    printed = steps.add_parser(
        "board",
        help="the ChArUco board as an image to print",
        description="Print it at 100 %% scale (no fitting to the page), glue it flat on "
        "something stiff, and measure a square: give that side with --square.",
    )
    printed.add_argument("-o", "--output", type=Path, required=True, help="PNG file")
    printed.add_argument("--force", action="store_true", help="write over an existing file")
    printed.add_argument("--dpi", type=_positive, default=300, help="printer dots per inch")
    _board_arguments(printed)
    ceiling = steps.add_parser(
        "ceiling",
        help="the camera's height and tilt over the floor, from the reference marker",
        description="The camera over the floor as the profile's reference marker F0 shows it, "
        "against the profile's scene.camera (level, at its position).",
    )
    ceiling.add_argument("profile", type=Path, help="deploy profile (its scene and tracker)")
    ceiling.add_argument(
        "--source", help="device, video or folder of images (default: the tracker's device)"
    )
    ceiling.add_argument(
        "--calibration", type=Path, help="intrinsics file (default: the tracker's)"
    )
    ceiling.add_argument("--frames", type=_positive, default=30, help="frames to read (default 30)")
    ceiling.add_argument("--json", action="store_true", help="print the result as JSON")
    return parser


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be 1 or more, got {value}")
    return value


def _board_arguments(parser: argparse.ArgumentParser) -> None:
    board = Board()
    across, down = board.squares
    parser.add_argument(
        "--squares",
        type=int,
        nargs=2,
        default=board.squares,
        metavar=("X", "Y"),
        help=f"the board's squares across and down (default {across} {down})",
    )
    parser.add_argument(
        "--square",
        type=float,
        default=board.square_m,
        help=f"a square's side, m (default {board.square_m})",
    )
    parser.add_argument(
        "--marker",
        type=float,
        default=board.marker_m,
        help=f"a marker's side, m (default {board.marker_m})",
    )
    parser.add_argument(
        "--dictionary", default=board.dictionary, help=f"ArUco dictionary ({board.dictionary})"
    )


def _board(args: argparse.Namespace) -> Board:
    """The arguments' board, once ``--output`` is known writable; ValueError says why not."""
    why = writable_output(args.output, [], args.force)
    if why is not None:
        raise ValueError(why)
    return Board(tuple(args.squares), args.square, args.marker, args.dictionary)


def print_board(args: argparse.Namespace) -> int:
    """The board's image at ``--dpi``, ``PRINT_MARGIN_M`` of white around it, as a PNG."""
    try:
        board = _board(args)
    except ValueError as error:
        print(f"calibrate: {error}", file=sys.stderr)
        return 2
    dots_per_m = args.dpi / 0.0254
    square, margin = round(board.square_m * dots_per_m), round(PRINT_MARGIN_M * dots_per_m)
    x, y = (n * square for n in board.squares)
    image = board.charuco().generateImage((x + 2 * margin, y + 2 * margin), marginSize=margin)
    _, png = cv2.imencode(".png", image)
    with written_whole(args.output) as partial:
        partial.write_bytes(png.tobytes())
    width, height = (1e3 * n * square / dots_per_m for n in board.squares)
    print(
        f"calibrate: {args.output}: {board.describe()}; printed at {args.dpi} dpi its squares "
        f"cover {width:.0f} x {height:.0f} mm",
        file=sys.stderr,
    )
    return 0


def _views(args: argparse.Namespace, board: Board) -> tuple[list[View], int, tuple[int, int]]:
    """The views with a board, the frames read and the image size (width, height)."""
    detector = BoardDetector(board)
    limit = args.frames or (DEVICE_FRAMES if args.source.isdigit() else sys.maxsize)
    views, read, size = [], 0, None
    for name, image in frames(args.source, limit, args.step, args.size):
        read += 1
        shape = (image.shape[1], image.shape[0])
        if size is None:
            size = shape
        elif shape != size:
            raise FrameSourceError(
                f"{name} is {shape[0]}x{shape[1]}, the first frame {size[0]}x{size[1]}"
            )
        view = detector.detect(name, image)
        if view is not None:
            views.append(view)
            print(f"calibrate: {name}: {len(view.image_points)} corners", file=sys.stderr)
    if not views:
        raise CalibrationRefused(f"no board ({board.describe()}) in the {read} frames read")
    return views, read, size


def _summary(result: Calibration, frames_read: int, output: Path) -> dict:
    i = result.intrinsics
    return {
        "fx": i.fx,
        "fy": i.fy,
        "cx": i.cx,
        "cy": i.cy,
        "distortion": list(i.distortion),
        "width": result.size[0],
        "height": result.size[1],
        "rms_px": result.rms_px,
        "views": result.views,
        "frames": frames_read,
        "std_px": dict(zip(("fx", "fy", "cx", "cy"), result.std_px, strict=True)),
        "span": list(result.span),
        "tilt_spread_deg": result.tilt_spread_deg,
        "worst_views": [{"view": name, "rms_px": rms} for name, rms in result.worst_views],
        "output": str(output),
    }


def calibrate_camera(args: argparse.Namespace) -> int:
    try:
        board = _board(args)
        views, read, size = _views(args, board)
        result = calibrate(evenly(views, args.max_views), size, k3=args.k3)
    except CalibrationRefused as error:
        print(f"calibrate: refused: {error}", file=sys.stderr)
        return 1
    except ValueError as error:  # the board's arguments, the source (FrameSourceError)
        print(f"calibrate: {error}", file=sys.stderr)
        return 2
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    comment = (
        f"Intrinsics of the ceiling camera (pixels) at {size[0]}x{size[1]}, from `parsimony "
        f"calibrate camera` on {stamp}:\n{result.views} views of a ChArUco board, RMS "
        f"reprojection error {result.rms_px:.3f} px;\nboard: {board.describe()}."
    )
    with written_whole(args.output) as partial:
        partial.write_text(camera_file_text(CameraFile(result.intrinsics, size), comment))
    summary = _summary(result, read, args.output)
    if args.json:
        emit(json_text(summary, indent=2))
        return 0
    i, s = result.intrinsics, result.std_px
    emit(
        f"fx {i.fx:.2f} fy {i.fy:.2f} cx {i.cx:.2f} cy {i.cy:.2f} px "
        f"(standard deviations {' '.join(f'{v:.2f}' for v in s)})\n"
        f"distortion k1 k2 p1 p2 k3: {' '.join(f'{k:.5f}' for k in i.distortion)}\n"
        f"RMS reprojection error {result.rms_px:.3f} px over {result.views} views "
        f"({read} frames, {size[0]}x{size[1]}); the worst: "
        + ", ".join(f"{name} {rms:.3f} px" for name, rms in result.worst_views)
        + f"\nwritten to {args.output}"
    )
    return 0


def run(args: argparse.Namespace) -> int:
    if args.what == "camera":
        return calibrate_camera(args)
    if args.what == "board":
        return print_board(args)
    try:
        return calibrate_ceiling(args)
    except (ProfileError, ValueError) as error:  # FrameSourceError, the intrinsics file
        print(f"calibrate: {error}", file=sys.stderr)
        return 2


def _camera_of(args: argparse.Namespace, profile: Profile) -> tuple[str, CameraFile]:
    """The frames' source and the intrinsics: the arguments', else the tracker's, else (no
    intrinsics file: synthetic frames) the scene's camera."""
    params = next((c.params for c in profile.components if c.module == "vision_tracker"), {})
    source = args.source or str(params.get("device", ""))
    if not source:
        raise ValueError("no source: give --source (the profile's tracker reads camera/image)")
    calibration = args.calibration or params.get("calibration")
    if calibration:
        return source, read_camera_file(Path(str(calibration)))
    c = profile.scene.camera
    print("calibrate: no intrinsics file: the scene's camera intrinsics", file=sys.stderr)
    return source, CameraFile(Intrinsics(c.fx, c.fy, c.cx, c.cy), (c.width, c.height))


def calibrate_ceiling(args: argparse.Namespace) -> int:
    profile = load_profile(args.profile)
    scene = profile.scene
    if scene is None:
        raise ValueError(f"{args.profile} has no scene (markers and camera)")
    source, camera = _camera_of(args, profile)
    detector = MarkerDetector(scene.dictionary_id)
    seen, read, size = [], 0, None
    for _, image in frames(source, args.frames, size=camera.size):
        read, size = read + 1, (image.shape[1], image.shape[0])
        seen += [d for d in detector.detect(image) if d.id == scene.reference.id]
    mismatch = camera.size_mismatch(*size)
    if mismatch:
        print(f"calibrate: {mismatch}", file=sys.stderr)
    if not seen:
        print(
            f"calibrate: refused: the reference marker (id {scene.reference.id}, "
            f"{scene.dictionary}) is in none of the {read} frames read",
            file=sys.stderr,
        )
        return 1
    ref = scene.reference
    found, pose_c = placement(seen, ref.size_m, ref.height_m, camera.intrinsics)
    x0, y0, yaw0 = scene.reference_pose
    measured = measured_camera(pose_c, (x0, y0, ref.height_m, yaw0), camera.intrinsics, size)
    try:
        shift = shift_of_seen_floor(ceiling_camera(scene.camera), measured, scene.base.height_m)
    except ValueError:
        shift = math.inf
    position = dq.translation(measured.pose)[1:]
    suggested = [round(float(v), 3) for v in (position[0], position[1], found.height_m)]
    warnings = []
    if shift > SEEN_FLOOR_TOLERANCE_M:
        warnings.append(
            f"the profile's camera (scene.camera.position {list(scene.camera.position)}, "
            f"level) sees the floor at the base marker's height up to {shift:.3f} m from where "
            f"this one does (over {SEEN_FLOOR_TOLERANCE_M} m): the sight region the supervisor "
            f"keeps the base in is off; set scene.camera.position to "
            f"{suggested}" + (" and level the camera" if found.tilt_deg > LEVEL_DEG else "")
        )
    summary = {
        **asdict(found),
        "frames": read,
        "reference_seen": len(seen),
        "seen_floor_shift_m": shift,
        "suggested_position": suggested,
        "warnings": warnings,
    }
    for warning in warnings:
        print(f"calibrate: warning: {warning}", file=sys.stderr)
    if args.json:
        emit(json_text(summary, indent=2))
    else:
        emit(f"{found.describe()} (F0 in {len(seen)} of {read} frames)")
    return 0
