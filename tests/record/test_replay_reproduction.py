"""A recorded lockstep experiment's sensors, replayed into a fresh vision tracker and state
estimator, give back the robot states it recorded: real processes, real Zenoh on loopback,
the real recording (the suite's shared pose run, its first seconds; issue 14: within 1 mm and
0.1 degree; a lockstep recording exactly)."""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import yaml
import zenoh

from messages import codec, topics
from messages.state import RobotState
from profiles.deploy_files import DEPLOY
from profiles.endpoints import free_port
from profiles.profile import load_profile
from record.sessions import load_session
from studies.launched import connect, wait_alive
from wbc import dq
from wbc.planar import wrap

POSITION_M = 1e-3
HEADING_RAD = math.radians(0.1)
SIM_S = 2.0
"""Simulated seconds of the recorded run whose states are compared: about 60 camera frames and
100 states."""
SENT_S = SIM_S + 1.0
"""Seconds of the recording replayed: those compared and a second more (what is logged after a
state's stamp, whatever it is, is sent)."""
RATE = 4.0
"""The replay's rate: ``--lockstep`` waits for the tracker's and estimator's answers to each
frame and odometry message, so the rate only bounds how fast the replay may go."""
DEADLINE_S = 60.0
ANSWER_WAIT_S = 30.0
"""How long the replay waits for each answer (``--answer-timeout``): a live loop that answers
slowly on a loaded machine still answers; only a dead one makes the replay go on."""


def complete_until(session: dict[str, list]) -> int:
    """The first stamp of a recorded state whose inputs are not all in the recording (its
    joints or odometry, or a camera frame the live tracker answered before it): the states
    before it can be reproduced; a larger stamp than any when none is missing."""
    joints = {m.header.stamp_ns for m in session["arm/joint_states"]}
    odometry = {m.header.stamp_ns for m in session["base/odometry"]}
    answered = {m.header.stamp_ns for m in session["vision/markers"]}
    lost_frames = sorted(answered - {m.header.stamp_ns for m in session["camera/image"]})
    first_lost = lost_frames[0] if lost_frames else math.inf
    for state in session["robot/state"]:
        stamp = state.header.stamp_ns
        if stamp not in joints or stamp not in odometry or stamp >= first_lost:
            return stamp
    return 1 + session["robot/state"][-1].header.stamp_ns


def estimators_profile(path: Path, namespace: str) -> Path:
    """A profile of only the simulation's vision tracker and state estimator, on ``namespace``
    and a fresh router."""
    path.write_text(
        yaml.safe_dump(
            {
                "extends": str(DEPLOY / "sim.yaml"),
                "namespace": namespace,
                "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
                "components": [
                    {"name": "simulator", "enabled": False},
                    {"name": "controller", "enabled": False},
                ],
            }
        )
    )
    enabled = {c.name for c in load_profile(path).components if c.enabled}
    assert enabled == {"vision_tracker", "state_estimator"}
    return path


def replay_into(profile_path: Path, recording: Path, stamps: set[int]) -> dict[int, RobotState]:
    """Launch the profile, replay the recording's sensors into it in lockstep, and return the
    robot states it published, by stamp, once those of ``stamps`` are all in."""
    profile = load_profile(profile_path)
    replayed: dict[int, RobotState] = {}
    arrived = threading.Condition()

    def take(sample: zenoh.Sample) -> None:
        state = codec.decode(sample.payload.to_bytes(), RobotState)
        with arrived:
            replayed[state.header.stamp_ns] = state
            arrived.notify_all()

    command = [sys.executable, "-m", "parsimony.cli"]
    with (profile_path.parent / "launch.log").open("w") as log:
        launcher = subprocess.Popen(
            [*command, "launch", str(profile_path)], stdout=log, stderr=subprocess.STDOUT
        )
    try:
        with connect(profile, launcher) as session:
            session.declare_subscriber(topics.ROBOT_STATE.key(profile.namespace), take)
            wait_alive(session, profile, launcher)
            done = subprocess.run(
                [
                    *command,
                    "replay",
                    str(recording),
                    "--profile",
                    str(profile_path),
                    "--sensors",
                    "--clock",
                    "--lockstep",
                    "--answer-timeout",
                    str(ANSWER_WAIT_S),
                    "--rate",
                    str(RATE),
                    "--duration",
                    str(SENT_S),
                ],
                capture_output=True,
                text=True,
            )
            assert done.returncode == 0, done.stderr
            assert "no answer" not in done.stderr, done.stderr
            with arrived:  # the replay had every answer; this subscription may trail it
                assert arrived.wait_for(lambda: stamps <= replayed.keys(), DEADLINE_S)
    finally:
        launcher.send_signal(signal.SIGINT)
        launcher.wait(DEADLINE_S)
    return replayed


def differences(recorded: RobotState, replayed: RobotState) -> tuple[float, float, float]:
    """Base position (m), heading (rad) and end-effector position (m) apart."""
    base = math.hypot(
        recorded.base_pose[0] - replayed.base_pose[0], recorded.base_pose[1] - replayed.base_pose[1]
    )
    heading = abs(wrap(recorded.base_pose[2] - replayed.base_pose[2]))
    tips = [dq.translation(np.array(s.end_effector)) for s in (recorded, replayed)]
    return base, heading, float(np.linalg.norm(tips[0] - tips[1]))


def test_replayed_sensors_reproduce_the_recorded_states_exactly(
    pose_lp_run: Path, tmp_path: Path
) -> None:
    report = json.loads((pose_lp_run / "report.json").read_text())
    assert report["mode"] == "lockstep" and report["lockstep_timeouts"] == 0, report
    recording = pose_lp_run / "session.mcap"
    session = load_session(recording)
    first = session["robot/state"][0].header.stamp_ns
    window = [s for s in session["robot/state"] if s.header.stamp_ns <= first + SIM_S * 1e9]
    end = complete_until(session)
    recorded = [s for s in window if s.header.stamp_ns < end]
    lost = f"the recorder lost inputs from {end / 1e9} s (a recording fault, not the replay's)"
    assert len(recorded) >= 0.9 * len(window) > 75, lost  # 2 s of 50 Hz states
    namespace = load_profile(pose_lp_run / "profile.yaml").namespace
    profile = estimators_profile(tmp_path / "estimators.yaml", namespace)
    replayed = replay_into(profile, recording, {s.header.stamp_ns for s in recorded})

    apart = [differences(s, replayed[s.header.stamp_ns]) for s in recorded]
    worst = [max(d[i] for d in apart) for i in range(3)]
    figures = (
        f"{len(recorded)} states; largest differences: base {worst[0] * 1e3:.4f} mm, "
        f"heading {math.degrees(worst[1]):.5f} deg, "
        f"end effector {worst[2] * 1e3:.4f} mm"
    )
    assert worst[0] <= POSITION_M and worst[1] <= HEADING_RAD and worst[2] <= POSITION_M, figures
    assert [s.valid for s in recorded] == [replayed[s.header.stamp_ns].valid for s in recorded]
    # A lockstep recording replayed in lockstep: the same inputs in the same order, exactly.
    different = [s.header.stamp_ns / 1e9 for s in recorded if s != replayed[s.header.stamp_ns]]
    assert not different, f"{len(different)} states differ, from {different[0]} s; {figures}"
