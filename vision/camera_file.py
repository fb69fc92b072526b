"""The intrinsics file of a camera (``deploy/lab/camera.yaml``), read and written.

``fx fy cx cy`` (px), an optional ``distortion`` (OpenCV's k1 k2 p1 p2 [k3]) and, in files
``parsimony calibrate camera`` writes, the image ``width`` and ``height`` the camera was
calibrated at (intrinsics in pixels hold at that size only). A file without a size, as written
by hand, stays valid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import yaml

from vision.markers import Intrinsics

DISTORTION_LENGTHS = (0, 4, 5, 8, 12, 14)
"""How many distortion coefficients OpenCV takes."""


@dataclass(frozen=True)
class CameraFile:
    """The intrinsics of a file and the image size they hold at ((width, height), or None)."""

    intrinsics: Intrinsics
    size: tuple[int, int] | None = None

    def size_mismatch(self, width: int, height: int) -> str:
        """Why an image of ``width`` x ``height`` does not fit these intrinsics; empty if it
        does (or the file gives no size)."""
        if self.size is None or self.size == (width, height):
            return ""
        return (
            f"the camera gives {width}x{height} images, its calibration is for "
            f"{self.size[0]}x{self.size[1]}: calibrate at this size or set the camera to that one"
        )


def _number(data: dict, key: str) -> float:
    value = float(data[key])
    if not math.isfinite(value):
        raise ValueError(f"{key} is {value}")
    return value


def read_camera_file(path: Path) -> CameraFile:
    """The file's intrinsics and size, or ``ValueError`` (``OSError``: it cannot be read)
    naming what is wrong."""
    try:
        data = yaml.safe_load(Path(path).read_text())
    except yaml.YAMLError as error:
        raise ValueError(f"{path} is not YAML: {error}") from error
    if not isinstance(data, dict):
        raise ValueError(f"{path} is not a mapping of fx, fy, cx, cy")
    try:
        fx, fy = _number(data, "fx"), _number(data, "fy")
        distortion = tuple(float(v) for v in data.get("distortion") or ())
        intrinsics = Intrinsics(fx, fy, _number(data, "cx"), _number(data, "cy"), distortion)
        size = None
        if "width" in data or "height" in data:
            size = (int(data["width"]), int(data["height"]))
    except KeyError as error:
        raise ValueError(f"{path} has no {error.args[0]}") from error
    except (TypeError, ValueError) as error:
        raise ValueError(f"{path}: {error}") from error
    if fx <= 0.0 or fy <= 0.0:
        raise ValueError(f"{path}: fx and fy must be positive, got {fx} and {fy}")
    if len(distortion) not in DISTORTION_LENGTHS or not all(map(math.isfinite, distortion)):
        raise ValueError(f"{path}: distortion must be 4, 5, 8, 12 or 14 finite numbers")
    if size is not None and min(size) <= 0:
        raise ValueError(f"{path}: width and height must be positive, got {size}")
    return CameraFile(intrinsics, size)


def _yaml_float(value: float) -> str:
    """Six significant digits, an exponent with a point (YAML 1.1 reads 1e-05 as a string)."""
    text = f"{value:.6g}"
    return text.replace("e", ".0e", 1) if "e" in text and "." not in text else text


def camera_file_text(camera: CameraFile, comment: str) -> str:
    """The file of ``camera`` in the layout of ``deploy/lab/camera.yaml``, ``comment`` (lines)
    at its head."""
    i = camera.intrinsics
    lines = [f"# {line}" for line in comment.splitlines()]
    lines += [f"fx: {i.fx:.4f}", f"fy: {i.fy:.4f}", f"cx: {i.cx:.4f}", f"cy: {i.cy:.4f}"]
    lines.append(f"distortion: [{', '.join(map(_yaml_float, i.distortion))}]")
    if camera.size is not None:
        lines += [f"width: {camera.size[0]}", f"height: {camera.size[1]}"]
    return "\n".join(lines) + "\n"
