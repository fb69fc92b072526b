"""A ROS 2 node on a Zenoh session, as rmw_zenoh_cpp 0.2.5 (Jazzy) makes one: its liveliness
token, publishers that put CDR (rosbags' serialiser) with the attachment on their topic's key,
and the tokens of its publishers and subscriptions, from which ``ros2 node list``, ``ros2 topic
list`` and rviz2 build the graph (``ros2.wire``).

A publisher with ``TRANSIENT_LOCAL`` durability (``/robot_description``, ``/tf_static``) is a
Zenoh advanced publisher with a cache of its depth and publisher detection, as rmw_zenoh
declares it since 0.2.2 (ros2/rmw_zenoh#469): a late joiner's advanced subscriber with history
gets the latest message from that cache. It numbers its samples for miss detection (a sporadic
heartbeat every ``HEARTBEAT_S``, as a reliable publisher of rmw_zenoh's), so that it needs no
timestamping in the session's configuration."""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass

import zenoh
import zenoh.ext

from ros2 import wire

TRANSIENT_LOCAL_QOS = ":1:,1:,:,:,,"
"""The compact QoS of a latched topic in a liveliness token: reliable (default), durability
TRANSIENT_LOCAL (1), keep last 1."""
DEFAULT_QOS = "::,10:,:,:,,"
"""The default profile's: reliable, volatile, keep last 10."""
SENSOR_QOS = "2::,5:,:,:,,"
"""sensor data's: best effort (2), volatile, keep last 5 (the camera)."""

HEARTBEAT_S = 0.5
MISS_DETECTION = zenoh.ext.MissDetectionConfig(heartbeat=None, sporadic_heartbeat=HEARTBEAT_S)


def gid(session_id: str, entity_id: int) -> bytes:
    """A publisher's 16-byte GID: the same for the same session and entity."""
    return hashlib.blake2b(f"{session_id}/{entity_id}".encode(), digest_size=wire.GID_SIZE).digest()


@dataclass
class Publisher:
    """One ROS 2 publisher: its key, type, sequence number and GID."""

    key: str
    msgtype: str
    gid: bytes
    zenoh_publisher: zenoh.Publisher | zenoh.ext.AdvancedPublisher
    sequence: int = 0

    def listened(self) -> bool:
        """Whether a subscriber matches this publisher's key (a ROS 2 node reads the topic)."""
        return self.zenoh_publisher.matching_status.matching

    def put(self, message: object) -> bytes:
        """Serialise ``message`` to CDR and put it with its attachment; the CDR bytes."""
        data = bytes(wire.typestore().serialize_cdr(message, self.msgtype))
        self.sequence += 1
        stamp = time.time_ns()
        self.zenoh_publisher.put(data, attachment=wire.attachment(self.sequence, stamp, self.gid))
        return data


class Participant:
    """A ROS 2 node named ``name`` of domain ``domain_id`` on ``session``; ``close`` undeclares
    its entities (closing the session does too)."""

    def __init__(self, session: zenoh.Session, name: str, domain_id: int) -> None:
        self.session = session
        self.node = wire.Node(str(session.zid()), name, domain_id=domain_id)
        self._next_id = self.node.node_id + 1
        self._declared: list[object] = [session.liveliness().declare_token(self.node.token())]

    def _entity(self, kind: str, topic: str, msgtype: str, qos: str) -> int:
        entity_id, self._next_id = self._next_id, self._next_id + 1
        token = self.node.entity_token(entity_id, kind, topic, msgtype, qos)
        self._declared.append(self.session.liveliness().declare_token(token))
        return entity_id

    def key(self, topic: str, msgtype: str) -> str:
        """The key of ``topic``'s data in this node's domain."""
        return wire.data_key(topic, msgtype, self.node.domain_id, self.node.namespace)

    def publisher(self, topic: str, msgtype: str, qos: str = DEFAULT_QOS) -> Publisher:
        """A publisher of ``msgtype`` on ``topic``; latched (an advanced publisher with a cache
        of one) when ``qos`` is ``TRANSIENT_LOCAL_QOS``."""
        key = self.key(topic, msgtype)
        entity_id = self._entity("MP", topic, msgtype, qos)
        if qos == TRANSIENT_LOCAL_QOS:
            declared = zenoh.ext.declare_advanced_publisher(
                self.session,
                key,
                cache=zenoh.ext.CacheConfig(1),
                publisher_detection=True,
                sample_miss_detection=MISS_DETECTION,
            )
        else:
            declared = self.session.declare_publisher(key)
        self._declared.append(declared)
        return Publisher(key, msgtype, gid(self.node.session_id, entity_id), declared)

    def subscription(self, topic: str, msgtype: str, on_sample, qos: str = DEFAULT_QOS) -> str:
        """Subscribe ``on_sample`` (a Zenoh callback, on Zenoh's thread) to ``topic`` of any type
        and hash (the callback checks them against ``key``); the key it matches."""
        self._entity("MS", topic, msgtype, qos)
        key = self.key(topic, msgtype).rsplit("/", 2)[0] + "/*/*"
        self._declared.append(self.session.declare_subscriber(key, on_sample))
        return key

    def close(self) -> None:
        """Undeclare every token, publisher and subscription."""
        for entity in reversed(self._declared):
            entity.undeclare()
        self._declared.clear()
