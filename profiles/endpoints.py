"""Zenoh endpoints, and which of them provably stay on this host."""

from __future__ import annotations

import ipaddress
import socket

LOCAL_PROTOCOLS = ("unixsock-stream",)
"""Zenoh link protocols that never leave the host."""
IP_PROTOCOLS = ("tcp", "udp", "tls", "quic", "ws")
"""Zenoh link protocols addressed by ``host:port``."""


def endpoint_problem(endpoint: str, needs_port: bool = False) -> str | None:
    """Why a Zenoh endpoint is not provably on this host, or None when it is.

    An endpoint is ``<protocol>/<address>[?<metadata>][#<config>]``. Local means a unix socket,
    or an IP protocol on a literal loopback address (127.0.0.0/8, ::1) with a port, and no
    metadata or config: an option such as ``#iface=eth0`` could bind it elsewhere, and a name
    such as ``localhost`` resolves through files and services outside the profile.
    ``needs_port``: port 0 (any free port) is refused, as for a router others connect to.
    """
    protocol, slash, address = endpoint.partition("/")
    if not slash or not address:
        return "expected <protocol>/<address>, e.g. tcp/127.0.0.1:7447"
    if "?" in address or "#" in address:
        return "metadata (?...) and options (#...) are not allowed on a local endpoint"
    if protocol in LOCAL_PROTOCOLS:
        return None
    if protocol not in IP_PROTOCOLS:
        return (
            f"unknown protocol {protocol!r} (expected one of {', '.join(IP_PROTOCOLS)} or "
            f"{', '.join(LOCAL_PROTOCOLS)})"
        )
    host, colon, port = address.rpartition(":")
    if not colon or not port.isdigit() or not 0 <= int(port) <= 65535:
        return "expected host:port with a port from 0 to 65535"
    if needs_port and int(port) == 0:
        return "port 0 picks a free port nobody knows; give the port others connect to"
    try:
        loopback = ipaddress.ip_address(host.removeprefix("[").removesuffix("]")).is_loopback
    except ValueError:
        return f"{host!r} is not a literal IP address (write 127.0.0.1 or [::1])"
    return None if loopback else f"{host} is not on the loopback interface"


def is_local_endpoint(endpoint: str) -> bool:
    """Whether a Zenoh endpoint (``tcp/127.0.0.1:7447``, ``unixsock-stream//tmp/s``) is local."""
    return endpoint_problem(endpoint) is None


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now (for a router's endpoint)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]
