"""The component runtime on real Zenoh sessions over loopback, in-process and as processes."""

from __future__ import annotations

import logging
import math
import signal
import threading
from typing import TYPE_CHECKING

import pytest

from components import rate_limited_log
from components.params import Param
from components.pubsub import Input
from components.rate_limited_log import RateLimitedLog
from components.runtime import WAITING_FOR_CLOCK, Node
from launch import query
from messages import codec, topics
from messages.base import IDENTITY_POSE
from messages.goal import Goal
from messages.header import Header
from messages.state import RobotState

if TYPE_CHECKING:
    from tests.components.conftest import System, WaitUntil


UNSTAMPED_SEQ = 10**9
"""A seq the publisher must overwrite with its own count."""


def robot_state(base_x: float = 0.25, valid: bool = True) -> RobotState:
    return RobotState(
        header=Header(stamp_ns=1, frame="world", seq=UNSTAMPED_SEQ, source="test"),
        base_pose=(base_x, 0.0, 0.0),
        arm_joints=(0.0, 0.1, 0.2, 0.3, 0.4),
        end_effector=IDENTITY_POSE,
        valid=valid,
        age_s=0.0,
    )


def test_typed_round_trip_between_two_nodes(system: System, wait_until: WaitUntil) -> None:
    received: list[RobotState] = []
    with Node(system.profile, "listener") as listener, Node(system.profile, "talker") as talker:
        subscription = listener.subscribe(topics.ROBOT_STATE, received.append)
        listener.start()
        publisher = talker.publisher(topics.ROBOT_STATE)
        talker.timer(0.02, lambda: publisher.put(robot_state()))
        talker.start()
        wait_until(lambda: len(received) >= 2, "two RobotStates")
        assert received[0].base_pose == (0.25, 0.0, 0.0)
        assert received[0].header.source == "test"
        seqs = [message.header.seq for message in received]
        assert seqs == sorted(set(seqs)) and seqs[-1] < UNSTAMPED_SEQ
        assert subscription.latest is not None and subscription.age_s() < system.deadline_s
    assert listener.counters["received.robot/state"] >= 1
    assert listener.counters["rejected.robot/state"] == 0


@pytest.mark.parametrize(("queue", "dropped"), [(None, "overwritten"), (4, "overflowed")])
def test_a_busy_handler_gets_the_newest_or_every_sample_and_drops_are_counted(
    system: System, wait_until: WaitUntil, queue: int | None, dropped: str
) -> None:
    """While the handler is busy, 12 samples arrive. The newest-only input hands it the last;
    a queue of 4 hands it the last 4 in order. Either way, handled + dropped = sent."""
    release = threading.Event()
    handled: list[float] = []

    def on_state(message: RobotState) -> None:
        handled.append(message.base_pose[0])
        release.wait(system.deadline_s)

    key = topics.ROBOT_STATE.key("test")
    with Node(system.profile, "listener") as listener:
        listener.subscribe(topics.ROBOT_STATE, on_state, queue=queue)
        listener.start()
        publisher = system.router.declare_publisher(key)
        wait_until(lambda: publisher.matching_status.matching, "the subscription to propagate")
        publisher.put(codec.encode(robot_state(base_x=0.0)))
        wait_until(lambda: handled == [0.0], "the first sample in the handler")
        for index in range(1, 12):
            publisher.put(codec.encode(robot_state(base_x=float(index))))
        counters = listener.counters
        sent = 12
        wait_until(
            lambda: counters[f"{dropped}.robot/state"] + len(handled) + (queue or 1) >= sent,
            "every sample kept or counted",
        )
        release.set()
        wait_until(
            lambda: counters[f"{dropped}.robot/state"] + len(handled) == sent,
            "the waiting samples handled",
        )
    kept = queue or 1
    assert handled == [0.0, *[float(i) for i in range(sent - kept, sent)]]
    assert counters[f"{dropped}.robot/state"] == sent - 1 - kept


def test_component_process_publishes_its_params_and_stops_on_sigterm(
    system: System, wait_until: WaitUntil
) -> None:
    goals: list[Goal] = []
    got_goal = threading.Event()
    liveliness = system.liveliness()
    process = system.start("pub")
    try:
        with Node(system.profile, "listener") as listener:
            state = listener.subscribe(topics.ROBOT_STATE)
            listener.subscribe(topics.CONTROL_GOAL, lambda g: (goals.append(g), got_goal.set()))
            listener.start()
            liveliness.wait_for("pub", alive=True)
            assert got_goal.wait(system.deadline_s), "no goal from the scripted publisher"
            wait_until(lambda: state.latest is not None, "a robot state")
        assert state.latest.base_pose == (1.5, 0.0, 0.0)
        assert state.latest.header.source == "pub"
        # pose at (1, 0, 0.5) without rotation: dual part = t / 2 = (0, 0.5, 0, 0.25)
        assert goals[0].task == "pose"
        assert goals[0].pose == (1.0, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.25)
        process.send_signal(signal.SIGTERM)
        assert process.wait(system.deadline_s) == 0
        liveliness.wait_for("pub", alive=False)
    finally:
        process.kill()
        process.wait()


def test_malformed_messages_are_dropped_counted_and_the_component_keeps_answering(
    system: System, wait_until: WaitUntil
) -> None:
    handled: list[RobotState] = []

    def on_state(message: RobotState) -> None:
        if not message.valid:
            raise RuntimeError("the handler refuses invalid states")
        handled.append(message)

    nan_state = RobotState.model_construct(**{**dict(robot_state()), "age_s": math.nan})
    key = topics.ROBOT_STATE.key("test")
    with Node(system.profile, "listener") as listener:
        listener.subscribe(topics.ROBOT_STATE, on_state)
        listener.start()
        publisher = system.router.declare_publisher(key)
        wait_until(lambda: publisher.matching_status.matching, "the subscription to propagate")
        counters = listener.counters
        for payload, counter, count in (
            (b"\x00garbage\xff", "rejected.robot/state", 1),
            (codec.encode(nan_state), "rejected.robot/state", 2),
            (codec.encode(robot_state(valid=False)), "errors.robot/state", 1),
            (codec.encode(robot_state(base_x=2.0)), "received.robot/state", 2),
        ):
            publisher.put(payload)
            wait_until(lambda c=counter, n=count: counters[c] == n, f"{counter} == {count}")
        assert [m.base_pose[0] for m in handled] == [2.0]
        status = query.statuses(system.router, "test")["listener"]
    assert status.state == "running"
    assert status.counters["rejected.robot/state"] == 2
    assert status.counters["errors.robot/state"] == 1
    assert status.counters["received.robot/state"] == 2


def test_sim_clock_drives_stamps_and_timers(system: System, wait_until: WaitUntil) -> None:
    profile = system.profile.model_copy(update={"clock": "sim"})
    fired: list[int] = []
    with Node(profile, "listener") as node:
        node.timer(0.1, lambda: fired.append(node.clock.now_ns()))
        node.start()
        clock = system.router.declare_publisher(topics.SIM_CLOCK.key("test"))
        wait_until(lambda: clock.matching_status.matching, "the clock subscription")
        assert node.header().stamp_ns == 0
        clock.put(codec.encode(topics.SIM_CLOCK.type(stamp_ns=50_000_000)))
        wait_until(lambda: node.clock.now_ns() == 50_000_000, "simulated time 0.05 s")
        assert fired == []
        clock.put(codec.encode(topics.SIM_CLOCK.type(stamp_ns=1_000_000_000)))
        wait_until(lambda: fired == [1_000_000_000], "the timer at simulated time 1 s")
        assert node.header("world").stamp_ns == 1_000_000_000


def test_a_stopped_sim_clock_is_reported_once_and_its_return_too(
    system: System, wait_until: WaitUntil
) -> None:
    profile = system.profile.model_copy(update={"clock": "sim", "clock_timeout_s": 0.2})
    stalls: list[float] = []
    with Node(profile, "listener") as node:
        node.start(on_clock_stall=stalls.append)
        wait_until(lambda: node.state == WAITING_FOR_CLOCK, "the wait for the first tick")
        clock = system.router.declare_publisher(topics.SIM_CLOCK.key("test"))
        wait_until(lambda: clock.matching_status.matching, "the clock subscription")
        clock.put(codec.encode(topics.SIM_CLOCK.type(stamp_ns=0)))
        wait_until(lambda: node.state == "clock stalled", "the stall to be noticed")
        wait_until(lambda: len(stalls) == 1, "the stall hook")
        assert stalls[0] >= 0.2 and node.counters["clock_stalls"] == 1
        assert query.statuses(system.router, "test")["listener"].state == "clock stalled"
        wait_until(lambda: clock.matching_status.matching, "the clock subscription")
        clock.put(codec.encode(topics.SIM_CLOCK.type(stamp_ns=10_000_000)))
        wait_until(lambda: node.state == "running", "the clock to move again")
        assert len(stalls) == 1


def test_the_publisher_of_sim_clock_runs_on_host_time(system: System) -> None:
    """A simulator or a replayer makes the time the others follow; it does not wait for it."""
    profile = system.profile.model_copy(update={"clock": "sim"})
    with Node(profile, "talker", reads=(), writes=(topics.SIM_CLOCK,)) as simulator:
        assert not simulator.clock.simulated
    with Node(profile, "listener", reads=(), writes=()) as follower:
        assert follower.clock.simulated


def test_declared_params_take_profile_values_and_reject_unknown_names(
    system: System, wait_until: WaitUntil
) -> None:
    declared = [Param("rate_hz", float, 1.0, low=0.1), Param("goal_task", str, "x")]
    node = Node(system.profile, "pub", declared + [Param("base_x", float, 0.0)])
    assert dict(node.params) == {"rate_hz": 50.0, "goal_task": "pose", "base_x": 1.5}
    try:
        Node(system.profile, "pub", declared)
    except ValueError as error:
        assert "base_x: unknown parameter" in str(error)
    else:
        raise AssertionError("an undeclared profile parameter was accepted")


def test_shutdown_runs_on_the_handler_thread_before_the_session_closes(system: System) -> None:
    threads: list[str] = []
    with Node(system.profile, "listener") as node:
        node.start(lambda: threads.append(threading.current_thread().name))
    assert threads == ["listener-handler"]
    assert node.session.is_closed()


def test_repeated_warnings_are_logged_once_then_summarised(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    now = [0]
    monkeypatch.setattr(rate_limited_log.time, "monotonic_ns", lambda: now[0])
    warnings = RateLimitedLog(logging.getLogger("test"), interval_s=5.0)
    for step_s in (0, 1, 2, 3, 6, 7):
        now[0] = step_s * 1_000_000_000
        warnings.warning("rejected.robot/state", f"bad message at {step_s} s")
    warnings.warning("errors.robot/state", "handler failed")
    assert [record.getMessage() for record in caplog.records] == [
        "bad message at 0 s",
        "bad message at 6 s (3 more since the last report)",
        "handler failed",
    ]


def test_a_node_refuses_topics_its_component_did_not_declare(system: System) -> None:
    reads = (Input(topics.ROBOT_STATE, queue=8),)
    with Node(system.profile, "listener", reads=reads, writes=(topics.CONTROL_GOAL,)) as node:
        node.subscribe(topics.ROBOT_STATE)
        assert "overflowed.robot/state" in node.counters  # the declared mode: a queue
        node.publisher(topics.CONTROL_GOAL)
        with pytest.raises(ValueError, match="reads control/goal without declaring it"):
            node.subscribe(topics.CONTROL_GOAL)
        with pytest.raises(ValueError, match="writes robot/state without declaring it"):
            node.publisher(topics.ROBOT_STATE)
