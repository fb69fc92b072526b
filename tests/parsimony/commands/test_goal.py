"""`parsimony goal` and `parsimony topic pub` on a launched simulation on the simulator's clock
(``deploy/sim_station.yaml``, whose goals come from the operator, in lockstep): what they send
is stamped in the session's simulated time; a reachable goal is reached, its phases said as
they come; a goal below the floor, or one no configuration reaches, is refused with why."""

from __future__ import annotations

import json
import math
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
import yaml
import zenoh

from launch import query
from messages import codec, topics
from messages.goal import Goal
from messages.state import RobotState
from profiles.deploy_files import DEPLOY
from profiles.endpoints import free_port
from profiles.profile import Profile, load_profile
from studies.launched import connect, launched, wait_alive, wait_reached
from tests.parsimony.in_process import completed as parsimony  # in this process: no Python start
from tests.parsimony.in_process import run_in_process
from wbc import dq
from wbc.planar import offset_of

COMMAND_S = 300.0
"""Host seconds a command may take before the test fails instead of hanging."""
REACHED_M = 0.03
"""The estimated gripper this close to the goal once `goal --wait` says reached."""


@dataclass
class Watched:
    """The latest simulated time, the latest valid state, and every goal request."""

    clock_ns: int | None = None
    state: RobotState | None = None
    requests: list[Goal] = field(default_factory=list)
    changed: threading.Condition = field(default_factory=threading.Condition)

    def wait(self, ready, what: str) -> None:
        with self.changed:
            assert self.changed.wait_for(ready, COMMAND_S), f"no {what} in {COMMAND_S} s"


@dataclass
class Station:
    path: Path
    profile: Profile
    session: zenoh.Session
    watched: Watched

    def key(self, topic: topics.Topic) -> str:
        return topic.key(self.profile.namespace)


def watch(session: zenoh.Session, namespace: str, watched: Watched) -> list:
    def on(topic: topics.Topic, take):
        def handler(sample: zenoh.Sample) -> None:
            with watched.changed:
                take(codec.decode(sample.payload.to_bytes(), topic.type))
                watched.changed.notify_all()

        return session.declare_subscriber(topic.key(namespace), handler)

    def state(message: RobotState) -> None:
        if message.valid:
            watched.state = message

    return [
        on(topics.SIM_CLOCK, lambda m: setattr(watched, "clock_ns", m.stamp_ns)),
        on(topics.ROBOT_STATE, state),
        on(topics.GOAL_REQUEST, watched.requests.append),
    ]


@pytest.fixture(scope="module")
def station(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Station]:
    directory = tmp_path_factory.mktemp("goal")
    path = directory / "station.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "extends": str(DEPLOY / "sim_station.yaml"),
                "namespace": "goalcommand",
                "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
                "startup_timeout_s": 60.0,
                "components": [
                    {
                        "name": "simulator",
                        # Paced at the wall clock's rate: the loop does not run flat out
                        # (two cores) while a test waits on a command or on the planner.
                        "params": {"lockstep": True, "real_time_factor": 1.0, "paused": True},
                    }
                ],
            }
        )
    )
    profile = load_profile(path)
    with (
        (directory / "launch.log").open("w") as log,
        launched(path, log) as launcher,
        connect(profile, launcher) as session,
    ):
        watched = Watched()
        subscribers = watch(session, profile.namespace, watched)
        wait_alive(session, profile, launcher)
        wait_reached(session, profile, launcher)
        query.set_param(session, profile.namespace, "simulator", "paused", "false")
        watched.wait(lambda: watched.state is not None, "valid robot state")
        yield Station(path, profile, session, watched)
        for subscriber in subscribers:
            subscriber.undeclare()


def test_topic_pub_stamps_a_header_it_makes_on_the_simulators_clock(station: Station) -> None:
    """Not the wall clock: a recording of the session would otherwise last 56 years."""
    published: list[Goal] = []
    key = station.key(topics.WORLD_GOAL)
    watched = station.watched

    def on_goal(sample: zenoh.Sample) -> None:
        goal = codec.decode(sample.payload.to_bytes(), Goal)
        if goal.header.source == "parsimony":
            with watched.changed:
                published.append(goal)
                watched.changed.notify_all()

    with watched.changed:
        before = watched.clock_ns
    assert before is not None
    subscriber = station.session.declare_subscriber(key, on_goal)
    try:
        result = parsimony(
            "topic",
            "pub",
            "world/goal",
            '{"task": "position", "position": [0.5, 0.0, 0.4]}',
            "--profile",
            str(station.path),
        )
        assert result.returncode == 0, result.stderr
        watched.wait(lambda: published, "published goal")
        with watched.changed:
            (goal,), after = published, watched.clock_ns
    finally:
        subscriber.undeclare()
    assert before <= goal.header.stamp_ns <= after, (before, goal.header.stamp_ns, after)
    # The estimator writes world/goal in this profile, and the user is told.
    assert f"warning: state_estimator writes {key} in this profile" in result.stderr


def gripper(station: Station) -> tuple[float, ...]:
    """(x, y, z, yaw, pitch, roll) of the estimated gripper in F0 now."""
    with station.watched.changed:
        state = station.watched.state
    assert state is not None
    return offset_of(np.array(state.end_effector))


def test_a_goal_is_sent_on_the_profiles_clock_and_reached(station: Station) -> None:
    x, y, z, yaw, _, _ = gripper(station)
    target = (round(x + 0.08, 4), round(y + 0.05, 4), round(z - 0.04, 4))
    with station.watched.changed:
        sent, before = len(station.watched.requests), station.watched.clock_ns
    result = parsimony(
        "goal",
        *(str(v) for v in target),
        "--yaw",
        f"{math.degrees(yaw) + 10.0:.2f}",
        "--wait",
        "--json",
        "--timeout",
        "60",
        "--profile",
        str(station.path),
    )
    assert result.returncode == 0, result.stderr
    outcome = json.loads(result.stdout)
    assert outcome["result"] == "reached" and outcome["topic"] == "goal/request", outcome
    # The phases as they came, on stderr: planning first, reached last.
    phases = [
        line.split()[3].rstrip(",")
        for line in result.stderr.splitlines()
        if line.startswith("goal: ") and " s " in line
    ]
    assert phases[0] == "planning" and phases[-1] == "reached", result.stderr
    (request,) = station.watched.requests[sent:]
    assert request.header.source == "parsimony" and request.task == "pose"
    with station.watched.changed:
        # Simulated, not Unix, time.
        assert before <= request.header.stamp_ns <= station.watched.clock_ns
        state = station.watched.state
    assert np.allclose(dq.translation(np.array(request.pose))[1:], target, atol=1e-9)
    hand = dq.translation(np.array(state.end_effector))[1:]
    assert np.linalg.norm(hand - np.array(target)) < REACHED_M


def test_a_goal_below_the_floor_is_refused_and_not_sent(station: Station) -> None:
    x, y, _, _, _, _ = gripper(station)
    sent = len(station.watched.requests)
    result = parsimony(
        "goal", f"{x:.3f}", f"{y:.3f}", "-0.1", "--wait", "--profile", str(station.path)
    )
    assert result.returncode == 1, result.stderr
    assert "goal refused: the goal is 0.100 m below the floor" in result.stderr
    assert len(station.watched.requests) == sent and "Traceback" not in result.stderr


def test_a_goal_no_configuration_reaches_is_unreachable_with_the_reason(
    station: Station,
) -> None:
    x, y, _, _, _, _ = gripper(station)
    result = parsimony(
        "goal",
        f"{x:.3f}",
        f"{y:.3f}",
        "1.5",
        "--wait",
        "--json",
        "--timeout",
        "60",
        "--profile",
        str(station.path),
    )
    assert result.returncode == 1, result.stderr
    outcome = json.loads(result.stdout)
    assert outcome["result"] == "unreachable" and outcome["reason"], outcome
    assert f"goal unreachable: {outcome['reason']}" in result.stderr


@pytest.mark.parametrize(
    ("argv", "error"),
    [
        (("0.5", "nan", "0.4"), "argument Y: expected a finite number, got 'nan'"),
        (("0.5", "0", "0.4", "--position", "--yaw", "30"), "--position takes no --yaw or --rpy"),
        (("0.5", "0", "0.4", "--yaw", "10", "--rpy", "0", "0", "10"), "not allowed with"),
        (
            ("0.5", "0", "0.4", "--wait", "--profile", "deploy/sim.yaml"),
            "--wait follows supervisor/status, and no component of deploy/sim.yaml writes it",
        ),
    ],
)
def test_goal_refuses_input_it_cannot_use_with_exit_2(
    argv: tuple[str, ...], error: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before anything is sent, and with no running system to ask."""
    code, _, err = run_in_process(["goal", *argv], capsys)
    assert code == 2 and error in err, err
