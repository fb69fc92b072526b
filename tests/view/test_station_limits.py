"""The control station of `parsimony view` against hostile clients, with Foxglove's own client
(``tests/foxglove_client``): a view and its station in this process on a real router, a real
component (an in-process node) answering its parameters. Every malformed set gets an answer
that says what is wrong in a few words; what a client sends never reaches Zenoh unbounded; the
station goes on after its Zenoh session fails; a client's goals are held to their rate."""

from __future__ import annotations

import base64
import json
import logging
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml
import zenoh

from components.params import Param
from components.runtime import Node
from messages import codec, topics
from messages.goal import Goal
from parsimony.commands.view import stopped
from profiles.endpoints import free_port
from profiles.profile import Profile, load_profile
from tests.foxglove_client.client import DEADLINE_S, FoxgloveClient, missing
from view.client_limits import GOAL_RATE, STATUS_CHARS
from view.control_station import ControlStation
from view.live_view import LiveView

NAMESPACE = "limits"
GOAL = json.dumps(
    {
        "frame_id": "world",
        "pose": {"position": {"x": 0.6, "y": 0.1, "z": 0.0}, "orientation": {"w": 1.0}},
    }
)
"""A good goal (with no robot state known, only the message is checked)."""


@dataclass
class View:
    profile: Profile
    station: ControlStation
    address: str
    node: Node
    router: zenoh.Session
    goals: list[Goal]
    """Every goal on goal/request, heard on the router's session."""
    live: LiveView


@pytest.fixture
def view(tmp_path: Path) -> Iterator[View]:
    """A view of namespace ``limits`` whose station has a session of its own, and ``ctl``, a
    node with parameters ``eta`` (a float in [0, 10]) and ``mode``."""
    assert not missing(), missing()
    path = tmp_path / "limits.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "namespace": NAMESPACE,
                "zenoh": {"mode": "client", "router": [f"tcp/127.0.0.1:{free_port()}"]},
                "components": [
                    {
                        "name": "ctl",
                        "module": "scripted_publisher",
                        "role": "tool",
                        "enabled": False,
                    }
                ],
            }
        )
    )
    profile = load_profile(path)
    params = (
        Param("eta", float, 0.5, low=0.0, high=10.0, doc="a gain"),
        Param("mode", str, "on", choices=("on", "off"), doc="a choice"),
    )
    goals: list[Goal] = []
    with (
        zenoh.open(profile.zenoh.router_config()) as router,
        Node(profile, "ctl", params) as node,
        zenoh.open(profile.zenoh.client_config()) as viewing,
    ):
        node.start()
        watcher = router.declare_subscriber(
            topics.GOAL_REQUEST.key(NAMESPACE),
            lambda sample: goals.append(codec.decode(sample.payload.to_bytes(), Goal)),
        )
        own = zenoh.open(profile.zenoh.client_config())
        station = ControlStation(own, profile)
        with LiveView(
            viewing,
            NAMESPACE,
            [],
            0,
            listener=station,
            capabilities=station.capabilities,
            encodings=station.encodings,
        ) as live:
            station.attach(live.server)
            yield View(profile, station, live.address, node, router, goals, live)
        station.close()
        watcher.undeclare()
        if station.session is own:  # else Zenoh panicked in it: it cannot even close
            own.close()


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


def test_after_its_session_fails_the_station_says_so_and_goes_on_on_a_new_one(
    view: View, caplog: pytest.LogCaptureFixture
) -> None:
    """After a panic in Zenoh, the session answers nothing again."""
    failed = view.station.session
    poison(failed)
    with caplog.at_level(logging.WARNING, "parsimony.view"), FoxgloveClient(view.address) as client:
        client.server_info()
        client.send("getParameters", names=[], id="all")
        listed = client.wait_for(
            lambda e: e["event"] == "parameterValues" and e.get("id") == "all", "every parameter"
        )
        assert {p["name"] for p in listed["parameters"]} == {"ctl.eta", "ctl.mode"}
        client.send(
            "advertise",
            topic=topics.GOAL_REQUEST.key(NAMESPACE),
            encoding="json",
            schemaName="foxglove.PoseInFrame",
        )
        channel = client.wait_for(lambda e: e["event"] == "advertised", "the channel")["channel"]
        client.send("publish", channel=channel, text=GOAL)
        client.wait_for(lambda e: e["event"] == "status" and "sent" in e["message"], "the goal")
    assert view.station.session is not failed and view.station.session_errors == 1
    assert not view.station.failed
    assert stopped(view.live, view.station, as_json=False) == 0  # the view goes on: exit 0
    assert [g.header.source for g in view.goals] == ["view"]
    errors = [r.getMessage() for r in caplog.records if r.levelno == logging.ERROR]
    assert len(errors) == 1 and "the control station's Zenoh session failed" in errors[0]


def poison(session: zenoh.Session) -> None:
    """Make Zenoh panic in ``session``: a key of more than 64 KiB (the station bounds what
    clients send, so only a test can)."""
    with pytest.raises(BaseException, match="DidntWrite"):  # noqa: B017 - pyo3's PanicException
        list(session.get(topics.param_key(NAMESPACE, "ctl", "x" * 65536), timeout=1.0))


def test_when_no_new_session_can_be_opened_each_goal_and_set_says_so(
    view: View, capsys: pytest.CaptureFixture[str]
) -> None:
    """And `parsimony view` says so when it stops, and exits 1."""
    with FoxgloveClient(view.address) as client:
        client.server_info()
        client.send(
            "advertise",
            topic=topics.GOAL_REQUEST.name,
            encoding="json",
            schemaName="foxglove.PoseInFrame",
        )
        channel = client.wait_for(lambda e: e["event"] == "advertised", "the channel")["channel"]
        view.station.session.close()
        view.router.close()  # and no router to open a new session with
        client.send("publish", channel=channel, text=GOAL)
        said = client.wait_for(lambda e: e["event"] == "status", "the goal's answer")["message"]
        assert "goal/request not sent: the view's Zenoh session failed: Unable to connect" in said
        _, said_then = answer(client, [{"name": "ctl.eta", "value": 0.7, "type": "float64"}], "set")
        assert len(said_then) == 1 and "the view's Zenoh session failed" in said_then[0]
    assert view.station.failed.startswith("the view's Zenoh session failed: Unable to connect")
    assert view.station.session_errors == 2 and not view.goals
    capsys.readouterr()
    assert stopped(view.live, view.station, as_json=True) == 1
    out, err = capsys.readouterr()
    done = json.loads(out)
    assert (done["goals_sent"], done["goals_refused"], done["goals_dropped"]) == (0, 0, 0)
    assert (done["session_errors"], done["errors"]) == (2, 0)
    assert done["session_failed"] == view.station.failed
    assert "0 goals sent, 0 refused, 0 dropped over their rate; 2 Zenoh session errors" in err
    assert f"view: {view.station.failed}" in err


def test_a_client_sending_goals_faster_than_their_rate_is_told_its_goals_are_dropped(
    view: View,
) -> None:
    sent = 30
    with FoxgloveClient(view.address) as client:
        client.server_info()
        client.send(
            "advertise",
            topic=topics.GOAL_REQUEST.name,
            encoding="json",
            schemaName="foxglove.PoseInFrame",
        )
        channel = client.wait_for(lambda e: e["event"] == "advertised", "the channel")["channel"]
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
