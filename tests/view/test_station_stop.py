"""The control station's stop control (``view.station_stop``), with Foxglove's own client on a
view in this process (``tests.view.test_station_limits``'s), a holder of the latch on its node:
set true, the namespace stops; false, it is released; anything else is refused saying why."""

from __future__ import annotations

import time

from components.stop_latch import StopLatch
from tests.foxglove_client.client import DEADLINE_S, FoxgloveClient
from tests.view.test_station_limits import View, answer, view  # noqa: F401 - the fixture


def test_the_station_stops_and_releases_the_namespace(view: View) -> None:  # noqa: F811
    latch = StopLatch(view.node)
    with FoxgloveClient(view.address) as client:
        client.server_info()
        values, said = answer(client, [{"name": "control/stop", "value": True}], "stop")
        assert [(v["name"], v["value"]) for v in values] == [("control/stop", True)]
        assert any("control/stop: stopped by" in s for s in said), said
        client.send("getParameters", names=["control/stop"], id="read")
        listed = client.wait_for(
            lambda e: e["event"] == "parameterValues" and e.get("id") == "read", "the stop"
        )
        assert [(p["name"], p["value"]) for p in listed["parameters"]] == [("control/stop", True)]
        assert latch.stopped and latch.state.header.source == view.station.user
        _, said = answer(client, [{"name": "control/stop", "value": "yes"}], "bad")
        assert any("control/stop = 'yes' refused: true or false" in s for s in said), said
        values, _ = answer(client, [{"name": "control/stop", "value": False}], "release")
        assert [(v["name"], v["value"]) for v in values] == [("control/stop", False)]
    deadline = time.monotonic() + DEADLINE_S
    while latch.stopped:  # the release on its way through the router
        assert time.monotonic() < deadline, "the release never came"
        time.sleep(0.01)
