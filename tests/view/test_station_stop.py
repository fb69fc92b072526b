"""The control station's stop control (``view.station_stop``), with Foxglove's own client on a
view in this process (``tests/view/conftest.py``), a holder of the latch on its node:
set true, the namespace stops; false, it is released; anything else is refused saying why."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from components.stop_latch import StopLatch
from tests.foxglove_client.client import DEADLINE_S, FoxgloveClient
from tests.view.station_client import answer

if TYPE_CHECKING:
    from tests.view.conftest import View


def test_the_station_stops_and_releases_the_namespace(view: View) -> None:
    latch = StopLatch(view.node)
    with FoxgloveClient(view.address) as client:
        client.server_info()
        start = len(client.events)
        values, _ = answer(client, [{"name": "control/stop", "value": True}], "stop")
        assert [(v["name"], v["value"]) for v in values] == [("control/stop", True)]
        client.wait_for(
            lambda e: e["event"] == "status" and "control/stop: stopped by" in e["message"],
            "the stop said",
            start,
        )
        client.send("getParameters", names=["control/stop"], id="read")
        listed = client.wait_for(
            lambda e: e["event"] == "parameterValues" and e.get("id") == "read", "the stop"
        )
        assert [(p["name"], p["value"]) for p in listed["parameters"]] == [("control/stop", True)]
        assert latch.stopped and latch.state.header.source == view.station.user
        start = len(client.events)
        answer(client, [{"name": "control/stop", "value": "yes"}], "bad")
        client.wait_for(
            lambda e: e["event"] == "status" and "'yes' refused: true or false" in e["message"],
            "the refusal",
            start,
        )
        values, _ = answer(client, [{"name": "control/stop", "value": False}], "release")
        assert [(v["name"], v["value"]) for v in values] == [("control/stop", False)]
    deadline = time.monotonic() + DEADLINE_S
    while latch.stopped:  # the release on its way through the router
        assert time.monotonic() < deadline, "the release never came"
        time.sleep(0.01)
