"""rmw_zenoh's wire format for ROS 2 Jazzy, as rmw_zenoh_cpp 0.2.5 (jazzy, 2025-06-18) writes it
and its docs/design.md describes it (the attachment's fixed layout since 0.2.4, ros2/rmw_zenoh
#605): the key expression of a topic's data, the liveliness tokens of a node and of its
publishers and subscribers (from which ``ros2 node list``, ``ros2 topic list`` and rviz2 build
the graph) and the attachment every publication carries. Type hashes (RIHS01, REP 2011) are
computed from the Jazzy message definitions by rosbags, not by this module."""

from __future__ import annotations

import struct
from dataclasses import dataclass
from functools import cache

from rosbags.typesys import Stores, get_typestore

DISTRIBUTION = "jazzy"
RMW_ZENOH_VERSION = "0.2.5"
LIVELINESS_PREFIX = "@ros2_lv"
GID_SIZE = 16
ENTITY_KINDS = ("NN", "MP", "MS", "SS", "SC")
"""Node, message publisher, message subscription, service server, service client."""

_ATTACHMENT = struct.Struct(f"<qqB{GID_SIZE}s")


class WireError(ValueError):
    """A name, type or attachment that rmw_zenoh's format cannot carry."""


@cache
def typestore():
    """rosbags' store of ROS 2 Jazzy's message definitions."""
    return get_typestore(Stores.ROS2_JAZZY)


def type_hash(msgtype: str) -> str:
    """The RIHS01 hash of a Jazzy message type such as ``std_msgs/msg/String``."""
    try:
        return typestore().hash_rihs01(msgtype)
    except KeyError:
        raise WireError(f"unknown ROS 2 {DISTRIBUTION} message type: {msgtype}") from None


def dds_type_name(msgtype: str) -> str:
    """``std_msgs/msg/String`` as DDS names it in CDR: ``std_msgs::msg::dds_::String_``."""
    parts = msgtype.split("/")
    if len(parts) != 3 or not all(parts):
        raise WireError(f"a ROS 2 type is package/msg/Name, got {msgtype!r}")
    package, kind, name = parts
    return f"{package}::{kind}::dds_::{name}_"


def _fully_qualified(name: str, namespace: str = "/") -> str:
    """A topic name with its namespace, absolute, without a trailing slash."""
    if not name or name.endswith("/") or "//" in name or " " in name:
        raise WireError(f"not a ROS 2 topic name: {name!r}")
    if name.startswith("/"):
        return name
    return f"{namespace.rstrip('/')}/{name}"


def mangle(name: str) -> str:
    """A name inside one chunk of a key expression: every ``/`` becomes ``%``, an empty name
    ``%``."""
    return name.replace("/", "%") or "%"


def data_key(topic: str, msgtype: str, domain_id: int = 0, namespace: str = "/") -> str:
    """``<domain_id>/<fully qualified name>/<DDS type name>/<type hash>``, the key a topic's
    messages are put on (the name without its leading slash)."""
    qualified = _fully_qualified(topic, namespace)
    return f"{domain_id}/{qualified[1:]}/{dds_type_name(msgtype)}/{type_hash(msgtype)}"


@dataclass(frozen=True)
class Node:
    """A ROS 2 node on a Zenoh session: the session's id (hex), the node's id in it, its
    name, namespace and SROS enclave."""

    session_id: str
    name: str
    node_id: int = 0
    namespace: str = "/"
    enclave: str = "/"
    domain_id: int = 0

    def _base(self, entity_id: int, kind: str) -> str:
        if kind not in ENTITY_KINDS:
            raise WireError(f"entity kind: expected one of {ENTITY_KINDS}, got {kind!r}")
        namespace = self.namespace.strip("/")
        enclave = self.enclave.strip("/")
        return "/".join(
            (
                LIVELINESS_PREFIX,
                str(self.domain_id),
                self.session_id,
                str(self.node_id),
                str(entity_id),
                kind,
                mangle(enclave and "/" + enclave),
                mangle(namespace and "/" + namespace),
                self.name,
            )
        )

    def token(self) -> str:
        """The node's liveliness token (kind NN; its entity id is its node id)."""
        return self._base(self.node_id, "NN")

    def entity_token(
        self, entity_id: int, kind: str, topic: str, msgtype: str, qos: str = "::,10:,:,:,,"
    ) -> str:
        """The liveliness token of a publisher (MP) or subscription (MS) of this node on
        ``topic``: the node's chunks, then the mangled topic, the DDS type, its hash and the
        QoS in rmw_zenoh's compact form (``qos``; the default is the default profile's, depth
        10)."""
        qualified = _fully_qualified(topic, self.namespace)
        chunks = (mangle(qualified), dds_type_name(msgtype), type_hash(msgtype), qos)
        return "/".join((self._base(entity_id, kind), *chunks))


def attachment(sequence_number: int, timestamp_ns: int, gid: bytes) -> bytes:
    """The attachment of one publication: the sequence number and the source timestamp (ns
    since the UNIX epoch), each int64 little-endian, then the publisher's GID as a length byte
    and its 16 bytes."""
    if len(gid) != GID_SIZE:
        raise WireError(f"a publisher's GID is {GID_SIZE} bytes, got {len(gid)}")
    return _ATTACHMENT.pack(sequence_number, timestamp_ns, GID_SIZE, gid)


def read_attachment(data: bytes) -> tuple[int, int, bytes]:
    """(sequence number, source timestamp ns, GID) of an attachment; ``WireError`` if it is
    not one."""
    if len(data) != _ATTACHMENT.size:
        raise WireError(f"an attachment is {_ATTACHMENT.size} bytes, got {len(data)}")
    sequence, stamp, length, gid = _ATTACHMENT.unpack(data)
    if length != GID_SIZE:
        raise WireError(f"an attachment's GID length is {GID_SIZE}, got {length}")
    return sequence, stamp, gid
