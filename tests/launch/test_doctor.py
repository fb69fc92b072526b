"""`parsimony doctor`'s checklist (launch/doctor.py) against emulated devices on
pseudo-terminals: all well on both Dynamixel protocols, and each broken set-up named with its
fix; never a packet that moves anything."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from launch.doctor import checklist, port_check
from launch.doctor_devices import Check
from profiles.profile import load_profile
from protocols import create_oi as oi
from sim2d.devices.pty_link import PtyLink
from tests.launch.doctor_bench import READS, Bench, Setup, bench


def run(tmp_path: Path, setup: Setup) -> tuple[list[Check], Bench]:
    with bench(tmp_path, setup) as devices:
        lines = checklist(load_profile(devices.profile))
    return lines, devices


def assert_nothing_moved(devices: Bench, protocol: int) -> None:
    """Only Pings and Reads reached the servos and only Sensors and Start the Create: every
    servo's torque is as it was (off), no joint and no wheel was commanded."""
    assert set(devices.chain.instructions) <= READS[protocol], devices.chain.instructions
    assert set(devices.create.opcodes) <= {oi.SENSORS, oi.START}, devices.create.opcodes
    assert devices.chain.counters["sync_writes"] == 0
    torque = 24 if protocol == 1 else 64
    assert all(servo.table[torque] == 0 for servo in devices.chain.servos)
    assert devices.arm.velocities == [0.0] * len(devices.arm.velocities)
    assert devices.wheels.commanded == []


def by_name(lines: list[Check]) -> dict[str, Check]:
    return {line.name: line for line in lines}


@pytest.mark.parametrize("protocol", [1, 2])
def test_every_device_answers_as_the_profile_expects(tmp_path: Path, protocol: int) -> None:
    lines, devices = run(tmp_path, Setup(protocol=protocol))
    faults = [line for line in lines if line.status == "fail"]
    assert faults == []
    named = by_name(lines)
    servos = [line for line in lines if line.name.startswith("servo ")]
    assert len(servos) == (4 if protocol == 2 else 5)
    model = "XM430-W350" if protocol == 2 else "AX-18A"
    assert all(model in line.detail and "torque off" in line.detail for line in servos)
    assert "OI mode passive" in named["create"].detail
    assert named["create battery"].detail.startswith("80 %")
    assert "640x480, as calibrated" in named["camera"].detail
    assert named["reference marker"].status == "ok"
    assert named["monotonic clock"].status == "ok"
    assert_nothing_moved(devices, protocol)


BROKEN = {
    "missing port": (Setup(arm_port="/dev/ttyUSB-none"), "arm port (arm_driver)", "no such device"),
    "another id": (Setup(ids=(1, 2, 3, 4, 6)), "servo 5 (q5)", "id 6 answers instead"),
    "another id, protocol 2": (
        Setup(protocol=2, ids=(11, 12, 13, 20)),
        "servo 14 (joint4)",
        "id 20 answers instead",
    ),
    "another baud rate": (Setup(baud=57_600), "servo 3 (q3)", "answer at 57600 baud"),
    "a wrong model": (Setup(model=(3, 29)), "servo 3 (q3)", "MX-28"),
    "a wrong model, protocol 2": (Setup(protocol=2, model=(12, 18)), "servo 12 (joint2)", "AX-18A"),
    "no camera": (Setup(device="9"), "camera device", "/dev/video9: no such device"),
    "a calibration for another resolution": (
        Setup(size=(1280, 720)),
        "camera",
        "the camera gives 640x480 images, its calibration is for 1280x720",
    ),
}


@pytest.mark.parametrize("case", BROKEN)
def test_a_broken_set_up_is_a_fault_named_with_its_fix(tmp_path: Path, case: str) -> None:
    setup, name, fault = BROKEN[case]
    lines, devices = run(tmp_path, setup)
    line = by_name(lines)[name]
    assert line.status == "fail" and fault in line.detail, line
    assert line.fix
    assert_nothing_moved(devices, setup.protocol)


def test_a_port_this_user_may_not_open_says_the_group_to_join(tmp_path: Path) -> None:
    port = tmp_path / "ttyUSB0"
    port.touch(mode=0o000)
    line = port_check("arm port", str(port))
    if line.status == "ok":
        pytest.skip("this user reads every file (root)")
    assert line.status == "fail" and "no read and write permission" in line.detail
    assert "usermod -aG" in line.fix or "log out and in" in line.fix


def test_a_port_another_process_holds_open_is_a_fault_naming_it(tmp_path: Path) -> None:
    link = PtyLink(tmp_path / "servos")
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys; f = open(sys.argv[1], 'rb'); print(1, flush=True); sys.stdin.read()",
            str(link.link),
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
    )
    try:
        assert holder.stdout.readline().strip() == b"1"  # the port is open
        line = port_check("arm port", str(link.link))
    finally:
        holder.communicate(b"")
        link.close()
    assert line.status == "fail" and f"pid {holder.pid}" in line.detail, line
    assert "stop it first" in line.fix


def test_a_parameter_the_driver_refuses_is_a_fault_not_a_traceback(tmp_path: Path) -> None:
    with bench(tmp_path, Setup()) as devices:
        profile = load_profile(devices.profile)
        arm = next(spec for spec in profile.components if spec.name == "arm_driver")
        arm.params["baud"] = 12
        lines = checklist(profile)
    line = by_name(lines)["arm_driver"]
    assert line.status == "fail" and "baud" in line.detail, line
