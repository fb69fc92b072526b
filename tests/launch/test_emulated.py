"""The hardware profile against emulated devices: the same drivers, tracker, estimator and
controller as on the real robot, the Create and the servos emulated byte for byte on
pseudo-terminals and moving the simulated world. Real processes, real Zenoh on loopback."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

from launch import query
from messages import codec, topics
from parsimony import cli
from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from profiles.profile_files import read_profile_data
from studies.launched import connect, launched
from tests.launch.emulated_profiles import emulated_profile


def components(path: Path) -> dict[str, dict]:
    return {c["name"]: c for c in read_profile_data(path)["components"]}


def test_emulated_differs_from_hardware_by_device_paths_and_camera_source_only() -> None:
    hardware, emulated = components(DEPLOY / "hardware.yaml"), components(DEPLOY / "emulated.yaml")
    changed = {
        name: {
            key
            for key in set(spec) | set(hardware[name])
            if spec.get(key) != hardware[name].get(key)
        }
        for name, spec in emulated.items()
    }
    assert changed.pop("simulator") == {"enabled", "module", "params"}  # the emulated robot
    for driver in ("base_driver", "arm_driver"):
        params = (emulated[driver]["params"], hardware[driver]["params"])
        assert {k for k in params[0] if params[0][k] != params[1].get(k)} == {"port"}
        # Started once the emulated robot, which makes their devices, is alive.
        assert changed[driver] == {"params", "after"} and emulated[driver]["after"] == ["simulator"]
    camera = (emulated["vision_tracker"]["params"], hardware["vision_tracker"]["params"])
    assert {k for k in camera[0] if camera[0][k] != camera[1].get(k)} <= {"device", "calibration"}
    assert {name for name, keys in changed.items() if keys} == {
        "base_driver",
        "arm_driver",
        "vision_tracker",
    }
    sim = components(DEPLOY / "sim.yaml")
    assert set(hardware) - set(sim) == {"base_driver", "arm_driver"}
    assert hardware["simulator"]["enabled"] is False
    for unchanged in ("state_estimator", "controller"):
        assert hardware[unchanged]["module"] == sim[unchanged]["module"]
    assert load_profile(DEPLOY / "emulated.yaml").clock == "wall"


def test_the_pose_experiment_converges_through_the_emulated_devices(tmp_path: Path) -> None:
    """In real time (the emulated devices keep the wall clock), on one seed's set-up: a second
    seed drew a like drive forward to a like bin and proved nothing more, for 24 s.

    Its launch of the emulated profile starts and stops without a word of failure. Before, the
    base driver started before its emulated device existed and logged `cannot open
    .../create2: No such file` at every start, and a clean stop logged `controller lost` before
    `controller stopped (0)`. (A launch of its own for that proved it again, for 40 s.)"""
    command = [
        sys.executable,
        "-m",
        "parsimony.cli",
        "experiment",
        "pose",
        "--profile",
        str(DEPLOY / "emulated.yaml"),
        "--realtime",
        "--seed",
        "1",
        "--json",
        "--out",
        str(tmp_path),
    ]
    done = subprocess.run(command, capture_output=True, text=True, timeout=300)
    report = json.loads(done.stdout)
    assert done.returncode == 0 and report["converged"], report
    assert report["contacts"] == 0
    assert report["joint_limit_violations"] == 0
    assert report["final_error"] < 0.02
    assert report["estimator_error"]["position_m"] < 0.02
    text = (tmp_path / "launch.log").read_text()
    assert "cannot open" not in text and "No such file" not in text, text
    assert re.search(r"\[launch\] \w+ lost", text) is None, text
    for name in ("simulator", "base_driver", "arm_driver", "controller"):
        assert f"[launch] {name} stopped (0)" in text
    assert text.index("[launch] simulator alive") < text.index("[launch] started base_driver")


def test_a_killed_controller_leaves_the_robot_stopped_by_its_drivers(tmp_path: Path) -> None:
    """The Create keeps its last Drive command for ever; the base driver's timeout stops it.
    Before, on the same launch, the emergency stop holds the robot still until its release
    (``stop_until_released``)."""
    path = emulated_profile(
        tmp_path, "killtest", {"name": "controller", "restart": {"policy": "never"}}
    )
    profile = load_profile(path)
    truth: list = []
    with launched(path) as launcher, connect(profile, launcher) as session:
        key = topics.SIM_TRUTH.key(profile.namespace)
        session.declare_subscriber(
            key, lambda s: truth.append(codec.decode(s.payload.to_bytes(), topics.SIM_TRUTH.type))
        )
        deadline = time.monotonic() + 60
        while not moving(truth):
            assert time.monotonic() < deadline and launcher.poll() is None, "never moved"
            time.sleep(0.1)
        stop_until_released(path, profile.namespace, session, truth, launcher)
        controller = query.statuses(session, profile.namespace)["controller"]
        os.kill(controller.pid, signal.SIGKILL)
        killed_ns = time.time_ns()  # the simulator keeps host time (host_epoch)
        # Command timeout 0.2 s, then the wheels decelerate at 1 m/s^2 from under 0.25 m/s:
        # the truth stamped from 0.6 s after the kill on, 0.9 s of it at 50 Hz however late.
        deadline = time.monotonic() + 60
        while len(settled := [t for t in truth if t.header.stamp_ns > killed_ns + 6e8]) <= 45:
            assert time.monotonic() < deadline and launcher.poll() is None, "no truth"
            time.sleep(0.1)
        xs = [t.base_pose[0] for t in settled]
        ys = [t.base_pose[1] for t in settled]
        assert max(xs) - min(xs) < 1e-4 and max(ys) - min(ys) < 1e-4, (xs[0], xs[-1])
        arm = [t.arm_joints for t in settled]
        assert max(abs(a - b) for a, b in zip(arm[0], arm[-1], strict=True)) < 0.01
        counters = query.statuses(session, profile.namespace)["base_driver"].counters
        assert counters["stops"] >= 1


def stop_until_released(path: Path, namespace: str, session, truth: list, launcher) -> None:
    """`parsimony stop`: the robot still (0.9 s of truth from 0.6 s after the stop on, the
    wheels decelerating first), the controller still sending, every holder saying who stopped
    it; `parsimony release`: it moves again."""
    assert cli.main(["stop", "--profile", str(path), "--reason", "test"]) == 0
    stopped_ns = time.time_ns()
    deadline = time.monotonic() + 60
    while len(still := [t for t in truth if t.header.stamp_ns > stopped_ns + 6e8]) <= 45:
        assert time.monotonic() < deadline and launcher.poll() is None, "no truth"
        time.sleep(0.1)
    xs, ys = [t.base_pose[0] for t in still], [t.base_pose[1] for t in still]
    assert max(xs) - min(xs) < 1e-4 and max(ys) - min(ys) < 1e-4, (xs[0], xs[-1])
    arm = [t.arm_joints for t in still]
    assert max(abs(a - b) for a, b in zip(arm[0], arm[-1], strict=True)) < 0.01
    found = query.statuses(session, namespace)
    assert found["simulator"].stop is None  # the emulated robot obeys its drivers alone
    for name in ("base_driver", "arm_driver", "controller"):
        assert found[name].stop is not None and found[name].stop.stopped, name
        assert found[name].state.endswith("stopped by operator"), found[name].state
    assert found["base_driver"].counters["refused_while_stopped"] > 0  # the controller sends
    assert cli.main(["release", "--profile", str(path)]) == 0
    released = len(truth)
    deadline = time.monotonic() + 60
    while not moving(truth[released:]):
        assert time.monotonic() < deadline and launcher.poll() is None, "never moved again"
        time.sleep(0.1)


def moving(truth: list) -> bool:
    """The base has moved over 2 cm and is still moving."""
    if len(truth) < 20:
        return False
    first, before, last = truth[0].base_pose, truth[-20].base_pose, truth[-1].base_pose
    return abs(last[0] - first[0]) > 0.02 and abs(last[0] - before[0]) > 1e-4
