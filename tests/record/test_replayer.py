"""What a replay sends from a file (record/replayer.py): the topics wanted, their span and
window, the namespace they were recorded in, each log time's messages with the sensors first.
(The pace's schedule is tested with the replay's keys, in test_replay_keys.)"""

from __future__ import annotations

from pathlib import Path

import pytest

from messages import topics
from record.replayer import SENSORS, Recording, sending_rank
from record.session_file import SessionWriter
from tests.record.session_messages import NAMESPACE, image, state


def test_a_recording_is_the_wanted_topics_their_span_and_the_sensors_first(
    tmp_path: Path,
) -> None:
    path = tmp_path / "session.mcap"
    with SessionWriter(path) as writer:
        for stamp in (10**9, 2 * 10**9, 3 * 10**9):
            writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(stamp))
            writer.write(topics.CAMERA_IMAGE.key(NAMESPACE), image(stamp))
    everything = Recording.of(path, lambda name: True)
    assert everything.names == {"robot/state", "camera/image"}
    assert (everything.start_ns, everything.end_ns) == (10**9, 3 * 10**9)
    assert everything.namespace() == NAMESPACE and everything.outside is None
    assert everything.window(0.5, 1.0) == (1_500_000_000, 2_500_000_000)
    assert everything.window(1.0, None) == (2 * 10**9, 3 * 10**9)
    assert everything.window(0.0, 60.0) == (10**9, 3 * 10**9)  # never past the last
    groups = list(everything.groups(*everything.window(0.5, None)))
    assert [[r.topic_name for r in group] for group in groups] == [
        ["camera/image", "robot/state"]
    ] * 2
    states = Recording.of(path, lambda name: name == "robot/state")
    assert states.names == {"robot/state"}


def test_a_recording_of_two_namespaces_asks_for_one(tmp_path: Path) -> None:
    path = tmp_path / "two.mcap"
    with SessionWriter(path) as writer:
        writer.write(topics.ROBOT_STATE.key("lab/a"), state(1))
        writer.write(topics.ROBOT_STATE.key("lab/b"), state(2))
    with pytest.raises(
        ValueError, match="recorded in the namespaces lab/a, lab/b: give --namespace"
    ):
        Recording.of(path, lambda name: True).namespace()


def test_the_sensors_go_first_in_their_order() -> None:
    assert [sending_rank(name) for name in SENSORS] == [0, 1, 2]
    assert sending_rank("robot/state") == sending_rank("sim/clock") == len(SENSORS)
