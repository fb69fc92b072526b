"""What a Foxglove client says to the control station of ``tests/view/conftest.py``'s view, and
what it is answered."""

from __future__ import annotations

import json

from tests.foxglove_client.client import FoxgloveClient

NAMESPACE = "limits"
"""The namespace of the view of ``tests/view/conftest.py``."""
GOAL = json.dumps(
    {
        "frame_id": "world",
        "pose": {"position": {"x": 0.6, "y": 0.1, "z": 0.0}, "orientation": {"w": 1.0}},
    }
)
"""A good goal (with no robot state known, only the message is checked)."""


def goal_channel(client: FoxgloveClient, topic: str) -> int:
    """The channel the client advertises to send pose goals on ``topic``, once the station
    took it."""
    client.send("advertise", topic=topic, encoding="json", schemaName="foxglove.PoseInFrame")
    return client.wait_for(lambda e: e["event"] == "advertised", "the channel")["channel"]


def statuses(client: FoxgloveClient, start: int = 0) -> list[str]:
    return [e["message"] for e in client.events[start:] if e["event"] == "status"]


def answer(client: FoxgloveClient, parameters: list[dict], id_: str) -> tuple[list, list[str]]:
    """The values a set answers, and the statuses said with them."""
    start = len(client.events)
    client.send("setParameters", parameters=parameters, id=id_)
    values = client.wait_for(
        lambda e: e["event"] == "parameterValues" and e.get("id") == id_,
        f"the answer to {id_}",
        start,
    )
    return values["parameters"], statuses(client, start)
