"""Foxglove's Teleop panel through the control station (``view.station_teleop``), with
Foxglove's own client on a view in this process (``tests/view/conftest.py``): a twist typed by
hand and the layout's panel's button each become a ``TeleopCommand``; anything else is refused
saying why."""

from __future__ import annotations

import json
import time
from typing import TYPE_CHECKING

from messages import codec, topics
from messages.teleop import TeleopCommand
from tests.foxglove_client.client import DEADLINE_S, FoxgloveClient
from tests.view.conftest import teleop_config
from view.foxglove_layout import layout

if TYPE_CHECKING:
    from tests.view.conftest import View


TWIST = "geometry_msgs/Twist"


def test_the_teleop_panel_drives_through_the_station(view: View) -> None:
    heard: list[TeleopCommand] = []
    watcher = view.router.declare_subscriber(
        topics.TELEOP_COMMAND.key(view.profile.namespace),
        lambda sample: heard.append(codec.decode(sample.payload.to_bytes(), TeleopCommand)),
    )
    panel = teleop_config(json.loads(layout(view.profile.namespace).to_json()))
    assert panel is not None
    with FoxgloveClient(view.address) as client:
        client.server_info()
        for topic in ("teleop/command", panel["topic"]):  # by hand, and the layout's panel
            client.send("advertise", topic=topic, encoding="json", schemaName=TWIST)
        channels = [
            client.wait_for(lambda e, t=t: e["event"] == "advertised" and e["topic"] == t, t)
            for t in ("teleop/command", panel["topic"])
        ]
        channel = channels[0]["channel"]
        twist = {"linear": {"x": 0.1, "y": 0, "z": 0}, "angular": {"x": 0, "y": 0, "z": -0.2}}
        client.send("publish", channel=channel, text=json.dumps(twist))
        up = {"linear": {"x": panel["upButton"]["value"], "y": 0, "z": 0}}
        client.send(
            "publish",
            channel=channels[1]["channel"],
            text=json.dumps({**up, "angular": {"x": 0, "y": 0, "z": 0}}),
        )
        start = len(client.events)
        client.send("publish", channel=channel, text='{"linear": 1}')
        client.wait_for(
            lambda e: e["event"] == "status" and "not a geometry_msgs/Twist" in e["message"],
            "the refusal",
            start,
        )
    deadline = time.monotonic() + DEADLINE_S
    while len(heard) < 2:
        assert time.monotonic() < deadline, "no teleop/command"
        time.sleep(0.01)
    watcher.undeclare()
    assert [(c.forward, c.turn, c.joint) for c in heard] == [
        (0.1, -0.2, ""),
        (panel["upButton"]["value"], 0.0, ""),
    ]
