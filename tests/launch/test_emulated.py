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
from collections.abc import Callable
from pathlib import Path

from launch import query
from messages import codec, topics
from parsimony import cli
from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from profiles.profile_files import read_profile_data
from sim2d.devices.servo_chain import ANSWER_TIMEOUT_S
from studies.launched import connect, launched
from tests.launch.emulated_profiles import emulated_profile

ARM_TIMEOUT = "answer_timeout_s"
DEADLINE_S = 60.0
"""A safety net only: each wait ends on what it waits for."""
STILL_TRUTHS = 45
"""0.9 s of the simulator's truth at 50 Hz."""


def components(path: Path) -> dict[str, dict]:
    return {c["name"]: c for c in read_profile_data(path)["components"]}


def test_emulated_differs_from_hardware_by_devices_camera_and_answer_timeout_only() -> None:
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
    for driver, differs in (("base_driver", {"port"}), ("arm_driver", {"port", ARM_TIMEOUT})):
        params = (emulated[driver]["params"], hardware[driver]["params"])
        assert {k for k in params[0] if params[0][k] != params[1].get(k)} == differs
        # Started once the emulated robot, which makes their devices, is alive.
        assert changed[driver] == {"params", "after"} and emulated[driver]["after"] == ["simulator"]
    # An emulated servo on a busy machine may answer late; a real one is awaited the SDK's time.
    assert emulated["arm_driver"]["params"][ARM_TIMEOUT] == ANSWER_TIMEOUT_S
    assert ARM_TIMEOUT not in hardware["arm_driver"]["params"]
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
    """The Create keeps its last Drive command for ever; the base driver's timeout stops it,
    and the arm driver's holds the arm. Before, on the same launch, the emergency stop holds the
    robot still until its release (``stop_until_released``). Each stillness is waited for from
    when the drivers say they stopped, not from a time after the kill or the stop that a busy
    machine's drivers may not keep."""
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
        deadline = time.monotonic() + DEADLINE_S
        while not moving(truth):
            assert time.monotonic() < deadline and launcher.poll() is None, "never moved"
            time.sleep(0.1)
        stop_until_released(path, profile.namespace, session, truth, launcher)
        found = query.statuses(session, profile.namespace)
        stops = found["base_driver"].counters["stops"]
        holds = found["arm_driver"].counters["holds"]
        os.kill(found["controller"].pid, signal.SIGKILL)
        stopped_ns = seen(
            session,
            profile.namespace,
            launcher,
            ("base_driver", "arm_driver"),
            lambda found: (
                found["base_driver"].counters["stops"] > stops
                and found["arm_driver"].counters["holds"] > holds
            ),
        )
        still(truth, stopped_ns, launcher)


def stop_until_released(path: Path, namespace: str, session, truth: list, launcher) -> None:
    """`parsimony stop`: every holder saying who stopped it, the robot still from then on (once
    the wheels have decelerated), the controller still sending; `parsimony release`: it moves
    again."""
    assert cli.main(["stop", "--profile", str(path), "--reason", "test"]) == 0
    holders = ("base_driver", "arm_driver", "controller")
    stopped_ns = seen(
        session,
        namespace,
        launcher,
        holders,
        lambda found: all(found[name].state.endswith("stopped by operator") for name in holders),
    )
    still(truth, stopped_ns, launcher)
    found = query.statuses(session, namespace)
    assert found["simulator"].stop is None  # the emulated robot obeys its drivers alone
    for name in holders:
        assert found[name].stop is not None and found[name].stop.stopped, name
        assert found[name].state.endswith("stopped by operator"), found[name].state
    assert found["base_driver"].counters["refused_while_stopped"] > 0  # the controller sends
    assert cli.main(["release", "--profile", str(path)]) == 0
    released = len(truth)
    deadline = time.monotonic() + DEADLINE_S
    while not moving(truth[released:]):
        assert time.monotonic() < deadline and launcher.poll() is None, "never moved again"
        time.sleep(0.1)


def seen(
    session, namespace: str, launcher, names: tuple[str, ...], done: Callable[[dict], bool]
) -> int:
    """The host time (ns, as the truth is stamped) when the statuses of the components
    ``names`` are first seen to be ``done``."""
    deadline = time.monotonic() + DEADLINE_S
    while True:
        found = query.statuses(session, namespace)
        if all(name in found for name in names) and done(found):
            return time.time_ns()
        assert time.monotonic() < deadline and launcher.poll() is None, "never stopped"
        time.sleep(0.05)


def still(truth: list, since_ns: int, launcher) -> None:
    """Wait for the robot to be still (the base within 0.1 mm, the arm within 0.01 rad) over
    STILL_TRUTHS truths in a row stamped after ``since_ns``; a robot that kept moving (the
    Create keeps its last Drive for ever) never is."""

    def found() -> bool:
        after = [t for t in truth if t.header.stamp_ns > since_ns]
        for start in range(len(after) - STILL_TRUTHS + 1):
            window = after[start : start + STILL_TRUTHS]
            base = [t.base_pose[:2] for t in window]
            arm = [t.arm_joints for t in window]
            if all(max(v) - min(v) < 1e-4 for v in zip(*base, strict=True)) and all(
                max(v) - min(v) < 0.01 for v in zip(*arm, strict=True)
            ):
                return True
        return False

    deadline = time.monotonic() + DEADLINE_S
    while not found():
        assert time.monotonic() < deadline and launcher.poll() is None, "never still"
        time.sleep(0.1)


def moving(truth: list) -> bool:
    """The base has moved over 2 cm and is still moving."""
    if len(truth) < 20:
        return False
    first, before, last = truth[0].base_pose, truth[-20].base_pose, truth[-1].base_pose
    return abs(last[0] - first[0]) > 0.02 and abs(last[0] - before[0]) > 1e-4
