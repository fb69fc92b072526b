"""A component's subscriptions (components.pubsub) on real Zenoh sessions over loopback: a busy
handler's samples kept or dropped as its input declares, malformed ones refused and counted,
topics the component did not declare refused."""

from __future__ import annotations

import math
import threading
from typing import TYPE_CHECKING

import pytest

from components.pubsub import Input
from components.runtime import Node
from launch import query
from messages import codec, topics
from messages.state import RobotState
from tests.components.plain_state import robot_state

if TYPE_CHECKING:
    from tests.components.conftest import System, WaitUntil


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
