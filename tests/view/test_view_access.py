"""`parsimony view` obeys ``zenoh.access``: a view whose user may not write goal/request offers
its clients no publishing (Foxglove's own client is told so when it tries), one whose user may
offers it; a parameter set from a client obeys ``access.parameters`` as the view's user."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
import zenoh

from components.params import Param
from components.runtime import Node
from profiles.endpoints import free_port
from profiles.profile import load_profile
from tests.foxglove_client.client import (
    DEADLINE_S,
    FoxgloveClient,
    RunningView,
    missing,
    running_view,
)

NAMESPACE = "guarded"


@pytest.fixture
def guarded(tmp_path: Path) -> Iterator[Path]:
    """A profile whose goal/request only the operator may write, whose ``cam``'s parameters the
    operator and the guest may set and every other component's the operator alone; its router,
    and ``ctl`` and ``cam``, each a node with a parameter ``gain`` of 0.5."""
    users = ("operator", "viewer", "guest", "ctl", "cam")
    (tmp_path / "credentials.txt").write_text("".join(f"{u}:{u}-secret\n" for u in users))
    path = tmp_path / "guarded.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "namespace": NAMESPACE,
                "zenoh": {
                    "mode": "client",
                    "router": [f"tcp/127.0.0.1:{free_port()}"],
                    "access": {
                        "credentials": "credentials.txt",
                        "writers": {"goal/request": ["operator"]},
                        "parameters": {"*": ["operator"], "cam": ["operator", "guest"]},
                    },
                },
                "components": [
                    {"name": name, "module": "scripted_publisher", "role": "tool", "enabled": False}
                    for name in ("ctl", "cam")
                ],
            }
        )
    )
    profile = load_profile(path)
    gain = Param("gain", float, 0.5, low=0.0, high=10.0, doc="a gain")
    with (
        zenoh.open(profile.zenoh.router_config(NAMESPACE)),
        Node(profile, "ctl", [gain]) as ctl,
        Node(profile, "cam", [gain]) as cam,
    ):
        ctl.start()
        cam.start()
        yield path


def view_as(user: str, profile: Path) -> contextlib.AbstractContextManager[RunningView]:
    """``parsimony view`` run by ``user``."""
    return running_view(profile, env={**os.environ, "PARSIMONY_USER": user}, timeout_s=DEADLINE_S)


def test_a_view_whose_user_may_not_write_goals_offers_no_publishing(guarded: Path) -> None:
    assert not missing(), missing()
    with view_as("viewer", guarded) as view:
        line = view.live_line
        assert "no publishing: viewer may not write goal/request" in line, line
        assert "parameters of every running component, read-only: viewer may set none" in line
        with FoxgloveClient(view.address) as client:
            info = client.server_info()
            assert "clientPublish" not in info["capabilities"]
            assert "parameters" in info["capabilities"]
            client.send(
                "advertise",
                topic=f"{NAMESPACE}/goal/request",
                encoding="json",
                schemaName="foxglove.PoseInFrame",
            )
            refused = client.wait_for(lambda e: e["event"] == "status", "the server's answer")
            assert "does not support clientPublish" in refused["message"]
    assert view.process.returncode == 0, view.err
    with view_as("operator", guarded) as view:
        assert "goals from clients on goal/request" in view.live_line, view.live_line
        assert "read-only" not in view.live_line
        with FoxgloveClient(view.address) as client:
            assert "clientPublish" in client.server_info()["capabilities"]
    assert view.process.returncode == 0, view.err


def set_gain(client: FoxgloveClient, component: str, gain: float) -> tuple[float, list[str]]:
    """The gain a set of ``component.gain`` answers, and the statuses said with it."""
    start = len(client.events)
    client.send(
        "setParameters",
        parameters=[{"name": f"{component}.gain", "value": gain, "type": "float64"}],
        id=component,
    )
    answer = client.wait_for(
        lambda e: e["event"] == "parameterValues" and e.get("id") == component, "the answer", start
    )
    said = [e["message"] for e in client.events[start:] if e["event"] == "status"]
    (value,) = answer["parameters"]
    return value["value"], said


def test_a_client_sets_only_the_parameters_the_views_user_may(guarded: Path) -> None:
    assert not missing(), missing()
    with view_as("viewer", guarded) as view, FoxgloveClient(view.address) as client:
        assert "parameters" in client.server_info()["capabilities"]  # to read them
        gain, said = set_gain(client, "ctl", 2.0)
        assert gain == 0.5 and len(said) == 1, said
        assert "parameters are read-only in this view: viewer may set no component's" in said[0]
    with view_as("guest", guarded) as view, FoxgloveClient(view.address) as client:
        client.server_info()
        gain, said = set_gain(client, "ctl", 2.0)
        assert gain == 0.5 and len(said) == 1, said
        assert "ctl.gain = 2.0 refused: guest may not set ctl's parameters" in said[0]
        assert set_gain(client, "cam", 2.0)[0] == 2.0
    with view_as("operator", guarded) as view, FoxgloveClient(view.address) as client:
        client.server_info()
        assert set_gain(client, "ctl", 3.0)[0] == 3.0
    assert view.process.returncode == 0, view.err
