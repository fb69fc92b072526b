"""The recording bench's floods (studies/bench/record_throughput.py): what counts as handled by
the recorder, and the small messages it is fed."""

from __future__ import annotations

from messages import topics
from messages.joints import JointStates
from messages.odometry import BaseOdometry
from messages.state import RobotState
from studies.bench.record_throughput import SMALL, handled, small_message


def test_a_message_is_handled_once_written_or_dropped_and_counted() -> None:
    counters = {
        "written": 10,
        "overflowed.robot/state": 2,
        "rejected.camera/image": 1,
        "errors.arm/joint_states": 3,
        "received": 99,
    }
    assert handled(counters) == 16
    assert handled({}) == 0


def test_the_floods_small_messages_are_of_their_topics_types_in_sequence() -> None:
    kinds = {
        topics.ARM_JOINT_STATES: JointStates,
        topics.BASE_ODOMETRY: BaseOdometry,
        topics.ROBOT_STATE: RobotState,
    }
    assert set(SMALL) == set(kinds)
    for topic in SMALL:
        sent = small_message(topic, 7)
        assert isinstance(sent, kinds[topic]) and sent.header.seq == 7
