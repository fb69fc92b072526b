"""The control station's Zenoh session (``view.station_session``), on a view in this process
(``tests/view/conftest.py``) with Foxglove's own client: after a panic in Zenoh the station
says so and goes on on a new session; when none can be opened, each goal and set says so, and
`parsimony view` exits 1 saying why."""

from __future__ import annotations

import json
import logging
from typing import TYPE_CHECKING

import pytest
import zenoh

from messages import topics
from parsimony.commands.view import stopped
from tests.foxglove_client.client import FoxgloveClient
from tests.view.station_client import GOAL, NAMESPACE, answer, goal_channel

if TYPE_CHECKING:
    from tests.view.conftest import View


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
        channel = goal_channel(client, topics.GOAL_REQUEST.key(NAMESPACE))
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
        channel = goal_channel(client, topics.GOAL_REQUEST.name)
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
