"""A ROS 2 node on a real Zenoh session (loopback, scouting off): its liveliness tokens, a
publisher's CDR with the attachment numbering its samples, a latched topic a late joiner gets,
a subscription to any type of a topic, and ``close`` taking every entity away."""

from __future__ import annotations

import threading
from collections.abc import Iterator

import pytest
import zenoh
import zenoh.ext

from ros2 import wire
from ros2.participant import TRANSIENT_LOCAL_QOS, Participant, gid

DOMAIN = 3
DEADLINE_S = 30.0
STRING = "std_msgs/msg/String"


@pytest.fixture
def session() -> Iterator[zenoh.Session]:
    config = zenoh.Config()
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')
    with zenoh.open(config) as opened:
        yield opened


def text(data: str):
    return wire.typestore().types[STRING](data=data)


def tokens(session: zenoh.Session) -> set[str]:
    return {str(r.ok.key_expr) for r in session.liveliness().get(f"{wire.LIVELINESS_PREFIX}/**")}


class Received:
    """Samples a callback was given, and a wait for the n-th."""

    def __init__(self) -> None:
        self.samples: list[zenoh.Sample] = []
        self._arrived = threading.Condition()

    def __call__(self, sample: zenoh.Sample) -> None:
        with self._arrived:
            self.samples.append(sample)
            self._arrived.notify_all()

    def wait(self, count: int) -> list[zenoh.Sample]:
        with self._arrived:
            assert self._arrived.wait_for(lambda: len(self.samples) >= count, DEADLINE_S)
            return list(self.samples)


def test_a_gid_is_sixteen_bytes_the_same_for_the_same_entity() -> None:
    assert len(gid("abc", 2)) == wire.GID_SIZE
    assert gid("abc", 2) == gid("abc", 2)
    assert len({gid("abc", 2), gid("abc", 3), gid("abd", 2)}) == 3


def test_the_node_and_each_entity_have_a_token_until_close(session: zenoh.Session) -> None:
    node = Participant(session, "parsimony", DOMAIN)
    node.publisher("chatter", STRING)
    node.subscription("goal_pose", "geometry_msgs/msg/PoseStamped", lambda _: None)
    found = tokens(session)
    prefix = f"{wire.LIVELINESS_PREFIX}/{DOMAIN}/{session.zid()}/"
    assert node.node.token() in found
    kinds = sorted(t.split("/")[5] for t in found if t.startswith(prefix))
    assert kinds == ["MP", "MS", "NN"]
    ids = [t.split("/")[4] for t in found if t.startswith(prefix)]
    assert len(set(ids)) == 3  # one entity id each
    node.close()
    assert tokens(session) == set()


def test_a_publisher_puts_cdr_with_numbered_attachments_on_its_key(session) -> None:
    node = Participant(session, "parsimony", DOMAIN)
    publisher = node.publisher("chatter", STRING)
    assert publisher.key == wire.data_key("chatter", STRING, DOMAIN)
    received = Received()
    with session.declare_subscriber(publisher.key, received):
        first = publisher.put(text("one"))
        publisher.put(text("two"))
        samples = received.wait(2)
    store = wire.typestore()
    assert [store.deserialize_cdr(s.payload.to_bytes(), STRING).data for s in samples] == [
        "one",
        "two",
    ]
    assert samples[0].payload.to_bytes() == first
    attached = [wire.read_attachment(s.attachment.to_bytes()) for s in samples]
    assert [sequence for sequence, _, _ in attached] == [1, 2]
    assert {g for _, _, g in attached} == {publisher.gid}
    assert attached[0][1] <= attached[1][1]  # stamps in order
    node.close()


def test_a_publisher_is_listened_once_a_subscriber_matches_its_key(session) -> None:
    node = Participant(session, "parsimony", DOMAIN)
    publisher = node.publisher("chatter", STRING)
    assert not publisher.listened()
    matched = threading.Event()
    listener = publisher.zenoh_publisher.declare_matching_listener(
        lambda status: status.matching and matched.set()
    )
    with session.declare_subscriber(publisher.key, lambda _: None):
        assert matched.wait(DEADLINE_S) and publisher.listened()
    listener.undeclare()
    node.close()


def test_a_late_joiner_gets_the_latest_of_a_latched_topic(session) -> None:
    node = Participant(session, "parsimony", DOMAIN)
    publisher = node.publisher("robot_description", STRING, TRANSIENT_LOCAL_QOS)
    publisher.put(text("<robot name='old'/>"))
    publisher.put(text("<robot name='new'/>"))
    received = Received()
    history = zenoh.ext.HistoryConfig(detect_late_publishers=True)
    with zenoh.ext.declare_advanced_subscriber(session, publisher.key, received, history=history):
        (sample,) = received.wait(1)[:1]
    data = wire.typestore().deserialize_cdr(sample.payload.to_bytes(), STRING).data
    assert data == "<robot name='new'/>"  # a cache of one: the latest only
    node.close()


def test_a_subscription_hears_its_topic_of_any_type_and_no_other(session) -> None:
    node = Participant(session, "parsimony", DOMAIN)
    received = Received()
    key = node.subscription("goal_pose", "geometry_msgs/msg/PoseStamped", received)
    assert key == f"{DOMAIN}/goal_pose/*/*"
    session.put(f"{DOMAIN}/other/std_msgs::msg::dds_::String_/RIHS01_x", b"no")
    session.put(wire.data_key("goal_pose", STRING, DOMAIN), b"yes")
    (sample,) = received.wait(1)
    assert sample.payload.to_bytes() == b"yes"
    node.close()
