"""The component runtime on real Zenoh sessions over loopback, in-process and as processes."""

from __future__ import annotations

import signal
import threading
from typing import TYPE_CHECKING

from components.params import Param
from components.runtime import WAITING_FOR_CLOCK, Node
from launch import query
from messages import codec, topics
from messages.goal import Goal
from messages.state import RobotState
from tests.components.plain_state import UNSTAMPED_SEQ, robot_state

if TYPE_CHECKING:
    from tests.components.conftest import System, WaitUntil


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
