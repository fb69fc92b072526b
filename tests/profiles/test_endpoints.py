"""Zenoh endpoints (profiles/endpoints.py): which provably stay on this host, and why the others
are refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from profiles.endpoints import is_local_endpoint
from tests.profiles.profile_yaml import PUB, refusal


@pytest.mark.parametrize(
    "endpoint",
    [
        "tcp/127.0.0.1:7447",
        "tcp/127.0.0.2:1",
        "tcp/[::1]:7447",
        "udp/127.0.0.1:0",
        "unixsock-stream//tmp/parsimony.sock",
    ],
)
def test_loopback_and_unix_socket_endpoints_are_local(endpoint: str) -> None:
    assert is_local_endpoint(endpoint)


@pytest.mark.parametrize(
    ("endpoint", "reason"),
    [
        ("tcp/127.0.0.1:7450#iface=eth0", "options (#...) are not allowed"),
        ("udp/127.0.0.1:7447#iface=lo", "options (#...) are not allowed"),
        ("tcp/127.0.0.1:7447?prio=1", "metadata (?...)"),
        ("tcp/localhost:7447", "not a literal IP address"),
        ("tcp/127.0.0.1", "host:port"),
        ("tcp/127.0.0.1:99999", "host:port"),
        ("serial//dev/ttyUSB0", "unknown protocol"),
        ("127.0.0.1:7447", "expected <protocol>/<address>"),
    ],
)
def test_endpoints_not_provably_local_are_refused_with_the_reason(
    tmp_path: Path, endpoint: str, reason: str
) -> None:
    assert not is_local_endpoint(endpoint)
    message = refusal(
        tmp_path, {"namespace": "sim", "zenoh": {"listen": [endpoint]}, "components": [PUB]}
    )
    assert "zenoh.listen[0]" in message and reason in message
