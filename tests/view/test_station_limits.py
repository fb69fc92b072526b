"""The control station of `parsimony view` against hostile clients, with Foxglove's own client
(``tests/foxglove_client``): a view and its station in this process on a real router, a real
component (an in-process node) answering its parameters (``tests/view/conftest.py``). Every
malformed set gets an answer that says what is wrong in a few words; what a client sends never
reaches Zenoh unbounded; a client's goals are held to their rate (the station after its Zenoh
session fails: ``test_station_session.py``)."""

from __future__ import annotations

import base64
import time
from typing import TYPE_CHECKING

from messages import topics
from tests.foxglove_client.client import DEADLINE_S, FoxgloveClient
from tests.view.station_client import GOAL, answer, goal_channel, statuses
from view.client_limits import GOAL_RATE, STATUS_CHARS

if TYPE_CHECKING:
    from tests.view.conftest import View

HOSTILE = [
    (
        {"name": "ctl." + "x" * 65536, "value": 1.0, "type": "float64"},
        "= 1.0 refused: a name of 65540 characters: at most 128",
    ),
    ({"name": "*.eta", "value": 1.0}, "*.eta = 1 refused: no running component has this"),
    ({"name": "**.eta", "value": 1.0}, "**.eta = 1 refused: no running component has this"),
    ({"name": "ctl/x.eta", "value": 1.0}, "ctl/x.eta = 1 refused: no running component"),
    (
        {"name": "ctl.eta", "value": base64.b64encode(b"\0\1\2").decode(), "type": "byte_array"},
        "ctl.eta = 3 bytes refused: a byte array is no parameter's value",
    ),
    (
        {"name": "ctl.mode", "value": "o" * 100_000},
        "ctl.mode = 'oooooooooooooooooooooooooooooooooooooooo... (100000 characters)' refused: "
        "a value of 100000 characters: at most 4096",
    ),
    (
        {"name": "ctl.eta", "value": -3.0, "type": "float64"},
        "ctl.eta = -3.0 refused: eta: expected a float in",
    ),
]
"""Parameter sets that cannot be, and what the station says of each (the first three panicked
Zenoh or raised in the view before, and no answer came)."""


def test_each_malformed_set_is_refused_saying_why_and_the_station_goes_on(view: View) -> None:
    kept = {
        "ctl.eta": [{"name": "ctl.eta", "type": "float64", "value": 0.5}],
        "ctl.mode": [{"name": "ctl.mode", "value": "on"}],
    }
    with FoxgloveClient(view.address) as client:
        client.server_info()
        for index, (parameter, said) in enumerate(HOSTILE):
            values, said_then = answer(client, [parameter], f"bad{index}")
            assert len(said_then) == 1 and said in said_then[0], said_then
            assert len(said_then[0]) <= STATUS_CHARS
            assert values == kept.get(parameter["name"], [])  # a known one's value is kept
        values, said_then = answer(
            client, [{"name": "ctl.eta", "value": 0.7, "type": "float64"}], "good"
        )
        assert values == [{"name": "ctl.eta", "type": "float64", "value": 0.7}], said_then
    assert view.node.params["eta"] == 0.7


def test_a_client_sending_goals_faster_than_their_rate_is_told_its_goals_are_dropped(
    view: View,
) -> None:
    sent = 30
    with FoxgloveClient(view.address) as client:
        client.server_info()
        channel = goal_channel(client, topics.GOAL_REQUEST.name)
        began = time.monotonic()
        for _ in range(sent):
            client.send("publish", channel=channel, text=GOAL)
        client.wait_for(
            lambda e: e["event"] == "status" and "dropped" in e["message"],
            "a goal dropped for its rate",
        )
        station = view.station
        deadline = time.monotonic() + DEADLINE_S
        while station.goals_sent + station.goals_dropped < sent:
            assert time.monotonic() < deadline, "not every goal was answered"
            time.sleep(0.01)
        elapsed_s = time.monotonic() - began
    # Whatever the machine's speed: no more than the rate lets through in the time it took.
    assert station.goals_sent <= GOAL_RATE.burst + GOAL_RATE.per_s * elapsed_s
    dropped = [m for m in statuses(client) if "dropped" in m]
    assert (
        "goal/request dropped: more than 1 goal/s (5 at once) from this client (1 dropped);"
        " the next is taken in " in dropped[0]
    )
