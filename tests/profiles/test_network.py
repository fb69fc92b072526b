"""A profile's Zenoh settings (profiles.network): remote endpoints, multicast and a router on
port 0 refused; the router's, components' and clients' configs on loopback without multicast,
peers behind the router linking directly."""

from __future__ import annotations

import json
import queue
import socket
import time
from pathlib import Path

import pytest
import zenoh

from profiles.network import ZenohSettings
from tests.profiles.profile_yaml import PUB, refusal


@pytest.mark.parametrize(
    "zenoh",
    [
        {"router": ["tcp/192.168.1.20:7447"]},
        {"router": ["tcp/0.0.0.0:7447"]},
        {"connect": ["tcp/[::]:7447"]},
        {"mode": "peer", "listen": ["udp/10.0.0.1:0"]},
        {"router": ["tcp/robot.local:7447"]},
        {"multicast_scouting": True},
    ],
)
def test_remote_endpoints_and_multicast_are_refused(
    tmp_path: Path, zenoh: dict[str, object]
) -> None:
    message = refusal(tmp_path, {"namespace": "sim", "zenoh": zenoh, "components": [PUB]})
    assert "allow_remote: true" in message
    assert ZenohSettings(**zenoh, allow_remote=True).allow_remote


def test_a_router_on_port_0_is_refused(tmp_path: Path) -> None:
    """Port 0 would bind some free port that no component knows to connect to."""
    message = refusal(
        tmp_path,
        {"namespace": "sim", "zenoh": {"router": ["tcp/127.0.0.1:0"]}, "components": [PUB]},
    )
    assert "zenoh.router[0]" in message and "port 0" in message


def test_zenoh_configs_stay_on_loopback_without_multicast() -> None:
    settings = ZenohSettings(router=["tcp/127.0.0.1:7500"], mode="peer")
    configs = {
        "router": settings.router_config(),
        "peer": settings.component_config(),
        "client": settings.client_config(),
    }
    for mode, config in configs.items():
        assert json.loads(config.get_json("mode")) == mode
        assert json.loads(config.get_json("scouting/multicast/enabled")) is False
        # Peers learn each other's (loopback) listen endpoints over their sessions.
        assert json.loads(config.get_json("scouting/gossip/enabled")) is (mode != "client")
    client_mode = ZenohSettings(router=["tcp/127.0.0.1:7500"], mode="client")
    for config in (client_mode.router_config(), client_mode.component_config()):
        assert json.loads(config.get_json("scouting/multicast/enabled")) is False
        assert json.loads(config.get_json("scouting/gossip/enabled")) is False
    assert json.loads(configs["router"].get_json("listen/endpoints")) == ["tcp/127.0.0.1:7500"]
    assert json.loads(configs["peer"].get_json("listen/endpoints")) == ["tcp/127.0.0.1:0"]
    assert json.loads(configs["client"].get_json("listen/endpoints")) == []
    assert json.loads(configs["client"].get_json("connect/endpoints")) == ["tcp/127.0.0.1:7500"]


def test_peers_behind_the_router_link_directly_on_loopback() -> None:
    """Two peer sessions and the launcher's router: samples flow, over a direct peer link."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    settings = ZenohSettings(router=[f"tcp/127.0.0.1:{port}"], mode="peer")
    received: queue.SimpleQueue[bytes] = queue.SimpleQueue()
    with (
        zenoh.open(settings.router_config()),
        zenoh.open(settings.component_config()) as sub_session,
        zenoh.open(settings.component_config()) as pub_session,
    ):
        sub_session.declare_subscriber("test/peer", lambda s: received.put(s.payload.to_bytes()))
        publisher = pub_session.declare_publisher("test/peer")
        deadline = time.monotonic() + 10.0
        while sub_session.info.zid() not in list(pub_session.info.peers_zid()):
            assert time.monotonic() < deadline, "the peers never linked directly"
            time.sleep(0.01)
        while not publisher.matching_status.matching:
            assert time.monotonic() < deadline, "the subscriber never matched"
            time.sleep(0.01)
        publisher.put(b"hello")
        assert received.get(timeout=5.0) == b"hello"
