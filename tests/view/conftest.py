"""A view and its control station in this process on a real router, with ``ctl``, a real
component (an in-process node) answering its parameters: the station's tests share it."""

from __future__ import annotations

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
from profiles.endpoints import free_port
from profiles.profile import Profile, load_profile
from tests.foxglove_client.client import missing
from tests.view.station_client import NAMESPACE
from view.control_station import ControlStation
from view.live_view import LiveView


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


def teleop_config(node: object) -> dict | None:
    """The config of the Teleop panel of a layout's document, None without one."""
    if isinstance(node, dict):
        if node.get("panelType") == "Teleop":
            return node["config"]
        node = list(node.values())
    if isinstance(node, list):
        for item in node:
            found = teleop_config(item)
            if found is not None:
                return found
    return None
