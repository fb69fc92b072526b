"""A hardware profile's devices, emulated for `parsimony doctor`'s tests: the servo chain (AX or
X series) and the Create on pseudo-terminals, and the ceiling camera as an image file of the
synthetic camera's view, with its calibration file. Each may be set up broken."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import yaml

from profiles.profile import load_profile
from protocols import dynamixel_v1 as dxl1
from protocols import dynamixel_v2 as dxl2
from sim2d.camera import ImageNoise, PlacedMarker, render
from sim2d.devices.ax_servos import AXChainEmulator
from sim2d.devices.create2 import Create2Emulator
from sim2d.devices.servo_chain import ANSWER_TIMEOUT_S, IntegratingJoints
from sim2d.devices.x_servos import XChainEmulator
from sim2d.pinhole import ceiling_camera
from wbc.planar import planar_pose
from wbc.servo_map import ServoMap

ROOT = Path(__file__).resolve().parents[2]
HARDWARE = ROOT / "deploy" / "hardware.yaml"
OMX = ROOT / "deploy" / "robots" / "open_manipulator_x.yaml"
LITTLE_JOHN = ROOT / "deploy" / "robots" / "little_john.yaml"
READS = {1: {dxl1.Instruction.PING, dxl1.Instruction.READ}, 2: {dxl2.Instruction.PING, 2}}
"""The only instructions doctor may send, per protocol (2.0's Read is 2 as well)."""


class StillWheels:
    """The Create's world: wheels that record what they are told and never turn."""

    def __init__(self) -> None:
        self.commanded: list[tuple[float, float]] = []

    def set_wheel_speeds(self, left: float, right: float) -> None:
        self.commanded.append((left, right))

    def encoder_counts(self) -> tuple[int, int]:
        return (0, 0)


@dataclass
class Setup:
    """What to break: ``ids`` of the chain (None: the robot's), the chain's ``baud``, a
    servo's ``model`` ((id, model number)), the camera ``device`` (None: the rendered view),
    the calibration's ``size``, and the arm port's name (``arm_port``, None: the chain's)."""

    protocol: int = 1
    ids: tuple[int, ...] | None = None
    baud: int = 1_000_000
    model: tuple[int, int] | None = None
    device: str | None = None
    size: tuple[int, int] | None = None
    arm_port: str | None = None


@dataclass
class Bench:
    profile: Path
    chain: AXChainEmulator | XChainEmulator
    create: Create2Emulator
    arm: IntegratingJoints
    wheels: StillWheels


def _camera_files(
    directory: Path, profile: Path, size: tuple[int, int] | None
) -> tuple[Path, Path]:
    """The synthetic ceiling camera's view of the floor reference as a PNG, and a calibration
    file of its intrinsics for ``size`` (None: the image's own)."""
    scene = load_profile(profile).scene
    camera = ceiling_camera(scene.camera)
    reference = PlacedMarker(
        scene.reference.id,
        scene.reference.size_m,
        planar_pose(*scene.reference_pose, scene.reference.height_m),
    )
    rng = np.random.default_rng(0)
    image = render(camera, [reference], scene.dictionary_id, ImageNoise(), rng)
    view = directory / "view.png"
    cv2.imwrite(str(view), image)
    width, height = size or (camera.width, camera.height)
    calibration = directory / "camera.yaml"
    c = scene.camera
    calibration.write_text(
        yaml.safe_dump(
            {"fx": c.fx, "fy": c.fy, "cx": c.cx, "cy": c.cy, "width": width, "height": height}
        )
    )
    return view, calibration


@contextlib.contextmanager
def bench(directory: Path, setup: Setup) -> Iterator[Bench]:
    """The emulated devices of ``setup`` running, and a profile that names them."""
    robot = OMX if setup.protocol == 2 else LITTLE_JOHN
    ids = setup.ids or ServoMap.of(robot, 4 if setup.protocol == 2 else 5).ids
    arm, wheels = IntegratingJoints([0.1] * len(ids)), StillWheels()
    chain_class = XChainEmulator if setup.protocol == 2 else AXChainEmulator
    chain = chain_class(arm, ids, directory / "servos", baud=setup.baud)
    if setup.model is not None:
        servo, model = setup.model
        next(s for s in chain.servos if s.id == servo).table[0:2] = model.to_bytes(2, "little")
    create = Create2Emulator(wheels, directory / "create2")
    data = {
        "extends": str(HARDWARE),
        "namespace": "doctor",
        "components": [
            {"name": "base_driver", "params": {"port": str(directory / "create2")}},
            {
                "name": "arm_driver",
                "params": {
                    "port": setup.arm_port or str(directory / "servos"),
                    "answer_timeout_s": ANSWER_TIMEOUT_S,
                },
            },
        ],
    }
    if setup.protocol == 2:
        data["robot"] = str(OMX)
        data["components"][1]["params"]["protocol"] = 2
    profile = directory / "profile.yaml"
    profile.write_text(yaml.safe_dump(data, sort_keys=False))
    view, calibration = _camera_files(directory, profile, setup.size)
    device = str(view) if setup.device is None else setup.device
    tracker = {"device": device, "calibration": str(calibration)}
    data["components"].append({"name": "vision_tracker", "params": tracker})
    profile.write_text(yaml.safe_dump(data, sort_keys=False))
    with chain, create:
        yield Bench(profile, chain, create, arm, wheels)
