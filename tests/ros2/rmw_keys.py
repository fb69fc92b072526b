"""For tests: the ROS 2 side of a Zenoh link as rmw_zenoh keys it (the domain, a topic's data
key from rosbags' type hash) and the attachment it puts beside each sample."""

from __future__ import annotations

import struct
import time

DOMAIN = 7
"""The ROS 2 domain the bridge's tests put it on."""
ATTACHMENT = struct.pack("<qqB16s", 1, time.time_ns(), 16, bytes(16))
"""A publisher's attachment as rmw_zenoh writes it: sequence number, source time, its GID."""


def store():
    """rosbags' Jazzy types (the independent serialiser)."""
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_JAZZY)


def design_key(topic: str, msgtype: str) -> str:
    """The data key as the design document writes it, from rosbags' hash."""
    package, _, name = msgtype.split("/")
    return f"{DOMAIN}/{topic}/{package}::msg::dds_::{name}_/{store().hash_rihs01(msgtype)}"
