"""Foxglove's Teleop panel through the control station (``view.control_station``): a client
advertises a channel on ``teleop/command`` (its key in the namespace, or its name) in JSON
``geometry_msgs/Twist``, as the panel publishes; each twist becomes a ``TeleopCommand`` (its
linear x the base's forward speed, its angular z the turn), which the controller applies under
the robot's limits and its dead-man timeout. Only a user who may command the robot may."""

from __future__ import annotations

import json
import math
import time

from messages import topics
from messages.header import Header
from messages.teleop import TeleopCommand

TWIST_SCHEMAS = ("geometry_msgs/Twist", "geometry_msgs/msg/Twist")
"""The schemas the Teleop panel names its messages with."""
TWIST_BYTES = 1024
"""The largest twist taken (a twist in JSON is about 100 bytes)."""

PANEL_RATE_HZ = 10.0
"""How often the layout's Teleop panel puts its twist while a button is held: five times
within the controller's dead-man timeout (``components.control_step.TELEOP_TIMEOUT_S``,
0.5 s), so that a held button drives without a pause."""
PANEL_FORWARD_M_S = 0.1
"""The forward (up) and back (down) speed of the panel and of ``parsimony teleop`` by default."""
PANEL_TURN_RAD_S = 0.5
"""The turn rate (left, right) of the panel and of ``parsimony teleop`` by default."""


def teleop_topic(topic: str, namespace: str) -> bool:
    """Whether a client's channel ``topic`` is ``teleop/command``."""
    return topic in (topics.TELEOP_COMMAND.name, topics.TELEOP_COMMAND.key(namespace))


def teleop_of(data: bytes, user: str) -> TeleopCommand:
    """The command of a JSON twist from ``user``'s view; ``ValueError`` saying what is wrong."""
    if len(data) > TWIST_BYTES:
        raise ValueError(f"a twist of {len(data)} bytes: at most {TWIST_BYTES}")
    try:
        twist = json.loads(data)
        forward, turn = float(twist["linear"]["x"]), float(twist["angular"]["z"])
    except (ValueError, TypeError, KeyError) as error:
        raise ValueError(f"not a geometry_msgs/Twist in JSON ({type(error).__name__})") from None
    if not (math.isfinite(forward) and math.isfinite(turn)):
        raise ValueError("a twist's linear.x and angular.z must be finite")
    header = Header(stamp_ns=time.time_ns(), frame="base", seq=0, source=user)
    return TeleopCommand(header=header, forward=forward, turn=turn)
