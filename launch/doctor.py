"""`parsimony doctor`'s checklist of a profile's hardware, each line ok, a warning or a fault
with its fix: the serial ports (there, and open to this user), the arm's servos and the Create
(``launch.doctor_devices``), the camera (it opens at its calibration's image size and sees the
reference marker) and the clocks. Nothing is started and nothing moves.

A fault is what stops the profile from running (a driver that cannot open its port, a servo
that does not answer as the arm driver expects, a camera that does not open or that its
calibration does not fit, the floor reference out of sight); a warning is what it runs with.
"""

from __future__ import annotations

import ctypes
import grp
import os
import time
from collections.abc import Callable
from pathlib import Path

import cv2

from components.params import Parameters
from launch.doctor_devices import Check, Joint, create_check, servo_checks
from launch.graph import component_class
from profiles.profile import ComponentSpec, Profile
from protocols import dynamixel_v1 as dxl1
from protocols import x_series_units as dxl2
from vision.camera_file import read_camera_file
from vision.frame_source import FrameSourceError, ask_size, open_capture
from vision.markers import MarkerDetector
from wbc.robot import BASE_DOF, MobileManipulator
from wbc.servo_map import ServoMap

CAMERA_FRAMES = 30
"""Frames read while looking for the reference marker (a camera's first ones may be dark)."""
TIME_ERROR = 5
"""adjtimex's answer when the system clock is not synchronised."""


def _params(spec: ComponentSpec) -> Parameters:
    return Parameters(component_class(spec).params, spec.params)


def _enabled(profile: Profile, module: str) -> list[ComponentSpec]:
    return [s for s in profile.components if s.enabled and s.module == module]


def port_check(name: str, path: str) -> Check:
    """The device file is there and this user may read and write it (else the group to
    join)."""
    device = Path(path)
    if not device.exists():
        what = "a dangling link" if device.is_symlink() else "no such device"
        return Check(
            name,
            "fail",
            f"{path}: {what}",
            "plug the device in (ls /dev/ttyUSB* /dev/ttyACM* /dev/video*) and set the "
            "profile's port (or device) to it",
        )
    if os.access(device, os.R_OK | os.W_OK):
        holders = holding(device)
        if holders:
            return Check(
                name,
                "fail",
                f"{path} is open in {'; '.join(holders)}",
                "stop it first (a running profile: doctor checks before the profile runs)",
            )
        return Check(name, "ok", f"{path} is there and open to this user")
    group = grp.getgrgid(device.stat().st_gid).gr_name
    user = os.environ.get("USER", "")
    if user in grp.getgrnam(group).gr_mem:
        fix = f"you are in {group} but this session is not yet: log out and in (or newgrp {group})"
    else:
        fix = f"join its group: sudo usermod -aG {group} $USER, then log out and in"
    return Check(name, "fail", f"{path}: no read and write permission (group {group})", fix)


def holding(device: Path) -> list[str]:
    """The other processes that hold ``device`` open ("pid N (command)"), as far as this
    user may see them in /proc."""
    target, holders = str(device.resolve()), []
    for fd_dir in Path("/proc").glob("[0-9]*/fd"):
        pid = int(fd_dir.parent.name)
        if pid == os.getpid():
            continue
        try:
            if any(os.readlink(fd) == target for fd in fd_dir.iterdir()):
                command = (fd_dir.parent / "cmdline").read_bytes().replace(b"\0", b" ")
                holders.append(f"pid {pid} ({command.decode(errors='replace').strip()[:60]})")
        except OSError:
            continue
    return holders


def _joints(profile: Profile, params: Parameters) -> list[Joint]:
    """Each arm joint's servo id and the Goal Positions the driver may write to it."""
    if profile.robot is None:
        raise ValueError("the arm driver needs the profile's `robot`")
    robot = MobileManipulator.from_yaml(profile.robot)
    servos = ServoMap.of(profile.robot, robot.arm_dof)
    if params["ids"]:
        servos = servos.with_ids(tuple(int(i) for i in params["ids"]))
    units = dxl1 if params["protocol"] == 1 else dxl2
    joints = []
    for index, name in enumerate(robot.joint_names):
        q = robot.q_min[BASE_DOF + index], robot.q_max[BASE_DOF + index]
        low, high = sorted(units.position_of_angle(servos.servo_angle(index, v)) for v in q)
        low_units = max(0, round(low))
        high_units = min(units.POSITION_MAX, round(high))
        joints.append(Joint(name, servos.ids[index], low_units, high_units))
    return joints


def arm_checks(profile: Profile, spec: ComponentSpec) -> list[Check]:
    params = _params(spec)
    port = str(params["port"])
    line = port_check(f"arm port ({spec.name})", port)
    if line.status == "fail":
        return [line]
    joints = _joints(profile, params)
    baud, protocol = int(params["baud"]), int(params["protocol"])
    return [line, *servo_checks(port, baud, protocol, joints, float(params["answer_timeout_s"]))]


def base_checks(spec: ComponentSpec) -> list[Check]:
    port = str(_params(spec)["port"])
    line = port_check(f"base port ({spec.name})", port)
    return [line] if line.status == "fail" else [line, *create_check(port)]


def camera_checks(profile: Profile, spec: ComponentSpec) -> list[Check]:
    """The capture device opens at the calibration's image size and sees the floor
    reference."""
    params = _params(spec)
    source, calibration = str(params["device"]), str(params["calibration"])
    if not source:
        return [Check("camera", "ok", "the tracker reads camera/image (a simulated camera)")]
    lines = []
    if source.isdigit():
        lines.append(port_check("camera device", f"/dev/video{source}"))
        if lines[0].status == "fail":
            return lines
    try:
        camera = read_camera_file(Path(calibration))
    except (OSError, ValueError) as error:
        fix = "write it with parsimony calibrate camera, or set vision_tracker's calibration"
        return [*lines, Check("camera calibration", "fail", str(error), fix)]
    try:
        capture = open_capture(source)
    except FrameSourceError as error:
        fix = "plug the camera in, or set vision_tracker's device to it"
        return [*lines, Check("camera", "fail", str(error), fix)]
    try:
        ask_size(capture, source, camera.size)
        image = None
        reference = profile.scene.reference
        detector = MarkerDetector(profile.scene.dictionary_id)
        seen = False
        for _ in range(CAMERA_FRAMES):
            ok, frame = capture.read()
            if not ok:
                break
            image = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) if frame.ndim == 3 else frame
            if any(d.id == reference.id for d in detector.detect(image)):
                seen = True
                break
    finally:
        capture.release()
    if image is None:
        fix = "check the camera (another program may hold it)"
        return [*lines, Check("camera", "fail", f"{source} opens but gives no frame", fix)]
    height, width = image.shape[:2]
    mismatch = camera.size_mismatch(width, height)
    if mismatch:
        fault, _, fix = mismatch.partition(": ")
        lines.append(Check("camera", "fail", fault, fix))
    elif camera.size is None:
        lines.append(
            Check(
                "camera",
                "warn",
                f"{source} gives {width}x{height} images; the calibration gives no image size, "
                "so whether it fits cannot be checked",
                "calibrate with parsimony calibrate camera (it writes the size)",
            )
        )
    else:
        lines.append(Check("camera", "ok", f"{source} gives {width}x{height}, as calibrated"))
    if seen:
        lines.append(Check("reference marker", "ok", f"marker {reference.id} (F0) in view"))
    else:
        lines.append(
            Check(
                "reference marker",
                "fail",
                f"marker {reference.id} (F0, {profile.scene.dictionary}) not in view",
                "put the floor reference under the camera, lit and unhidden",
            )
        )
    return lines


def clock_checks(profile: Profile) -> list[Check]:
    """The clocks the profile runs on. The servos and the Create carry no clock: their
    readings, and the camera's frames, are stamped by this host as they come, so only the
    host's clocks matter: the monotonic one (periods and timeouts) and, with stamps compared
    between computers, the system clock's synchronisation."""
    info = time.get_clock_info("monotonic")
    before = time.monotonic_ns()
    advances = time.monotonic_ns() >= before
    lines = [
        Check(
            "monotonic clock",
            "ok" if advances and info.monotonic else "fail",
            f"{info.implementation}, resolution {info.resolution * 1e9:.0f} ns",
            "" if advances and info.monotonic else "this system has no monotonic clock",
        )
    ]
    synchronised = _synchronised()
    if synchronised is None:
        lines.append(Check("system clock", "ok", "synchronisation unknown on this system"))
    elif synchronised:
        lines.append(Check("system clock", "ok", "synchronised (NTP)"))
    else:
        lines.append(
            Check(
                "system clock",
                "warn",
                f"not synchronised; the profile stamps on {profile.clock} time, so stamps "
                "compared with another computer's (a second host, a recording) may be off",
                "enable NTP: timedatectl set-ntp true",
            )
        )
    return lines


def _synchronised() -> bool | None:
    """Whether the kernel says the system clock is synchronised (adjtimex, read only)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        buffer = ctypes.create_string_buffer(512)  # struct timex, modes 0: a read
        state = libc.adjtimex(buffer)
    except (OSError, AttributeError):
        return None
    return None if state < 0 else state != TIME_ERROR


def checklist(profile: Profile, say: Callable[[Check], None] = lambda check: None) -> list[Check]:
    """Every line of the profile's checklist, ``say`` called with each as it is known."""
    lines: list[Check] = []

    def add(checks: list[Check]) -> None:
        for check in checks:
            lines.append(check)
            say(check)

    checks = {
        "arm_driver": lambda spec: arm_checks(profile, spec),
        "base_driver": base_checks,
        "vision_tracker": lambda spec: camera_checks(profile, spec),
    }
    for module, check in checks.items():
        for spec in _enabled(profile, module):
            try:
                add(check(spec))
            except ValueError as error:  # ParamError, RobotDescriptionError: the profile's
                fix = "correct the profile (parsimony launch refuses it too)"
                add([Check(spec.name, "fail", str(error).splitlines()[0], fix)])
    add(clock_checks(profile))
    return lines
