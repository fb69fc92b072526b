"""A profile's network: how its processes reach each other over Zenoh.

Endpoints must be on the loopback interface (or a unix socket) and multicast scouting is off,
unless the profile says ``allow_remote: true``: running across hosts is an explicit choice.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

import zenoh
from pydantic import Field, model_validator

from profiles.access import AccessSettings, insert
from profiles.endpoints import endpoint_problem
from profiles.strict import StrictModel


class TlsSettings(StrictModel):
    """TLS for the ``tls/...`` endpoints: the CA every session trusts, and the certificate
    and key a router listening on TLS presents (paths relative to the profile)."""

    root_ca_certificate: Path
    listen_certificate: Path | None = None
    listen_private_key: Path | None = None

    def json(self) -> dict[str, str]:
        return {name: str(value) for name, value in self.model_dump().items() if value}


class ZenohSettings(StrictModel):
    """How the processes of a profile reach each other.

    The launcher opens a router listening on ``router``; components open a
    ``mode`` session connecting to ``connect`` (the router endpoints when
    omitted). Peer-mode components also listen on ``listen``.

    In ``peer`` mode (the default) the router and the peers gossip their listen
    endpoints over the sessions they already have (never multicast), so every
    pair of components opens a direct link and a sample takes one hop instead of
    two through the router; the router brokers between peers that have no
    direct link yet. Without gossip a Zenoh router does not route between two
    peers at all. Every endpoint gossiped is one of the profile's, all on the
    loopback interface unless ``allow_remote``. ``client`` mode routes every
    sample through the router.
    """

    mode: Literal["client", "peer"] = "peer"
    router: list[str] = Field(default=["tcp/127.0.0.1:7447"], min_length=1)
    connect: list[str] | None = None
    listen: list[str] = ["tcp/127.0.0.1:0"]
    multicast_scouting: bool = False
    allow_remote: bool = False
    access: AccessSettings | None = None
    """Authentication and per-topic write rights (``profiles.access``); needs client mode."""
    uplinks: list[str] = []
    """Routers on other hosts that the launcher's router connects to (a lab of several
    computers); remote, so they need ``allow_remote``."""
    tls: TlsSettings | None = None

    @model_validator(mode="after")
    def _local_unless_allowed(self) -> ZenohSettings:
        if self.access is not None and self.mode != "client":
            raise ValueError(
                "access: the router's rules only see what passes through it; set mode: client"
            )
        if self.allow_remote:
            return self
        if self.multicast_scouting:
            raise ValueError("multicast_scouting: reaches other hosts; it needs allow_remote: true")
        for field in ("router", "connect", "listen", "uplinks"):
            for index, endpoint in enumerate(getattr(self, field) or ()):
                problem = endpoint_problem(endpoint, needs_port=field != "listen")
                if problem is not None:
                    raise ValueError(
                        f"{field}[{index}]: {endpoint!r}: {problem}; only 127.0.0.1, [::1] "
                        "or unixsock-stream are local; set allow_remote: true to run across hosts"
                    )
        return self

    @property
    def connect_endpoints(self) -> list[str]:
        """Where component and tool sessions connect."""
        return self.router if self.connect is None else self.connect

    def router_config(self, namespace: str = "") -> zenoh.Config:
        """The config of the launcher's router session (its access rules act on ``namespace``)."""
        config = self._config("router", listen=self.router, connect=self.uplinks)
        # Zenoh's open waits scouting/delay (0.5 s) for peers to find it before it returns; the
        # router needs none to route, and the peers that connect to it say so by their
        # liveliness tokens, which the launcher waits on.
        config.insert_json5("scouting/delay", "0")
        if self.access is not None:
            insert(config, self.access.router_json(namespace))
        return config

    def client_config(self, user: str | None = None) -> zenoh.Config:
        """The config of a client session: a tool's such as ``parsimony status`` (``user``
        None), or a client-mode component's."""
        config = self._config("client", listen=[], connect=self.connect_endpoints)
        if self.access is not None:
            insert(config, self.access.session_json(user))
        return config

    def component_config(self, name: str | None = None) -> zenoh.Config:
        """The config of component ``name``'s session, in the profile's ``mode``."""
        if self.mode == "client":
            return self.client_config(name)
        return self._config("peer", listen=self.listen, connect=self.connect_endpoints)

    def _config(self, mode: str, listen: list[str], connect: list[str]) -> zenoh.Config:
        config = zenoh.Config()
        config.insert_json5("mode", json.dumps(mode))
        config.insert_json5("listen/endpoints", json.dumps(listen))
        config.insert_json5("connect/endpoints", json.dumps(connect))
        config.insert_json5("scouting/multicast/enabled", json.dumps(self.multicast_scouting))
        gossip = self.allow_remote or (self.mode == "peer" and mode != "client")
        config.insert_json5("scouting/gossip/enabled", json.dumps(gossip))
        if self.tls is not None:
            config.insert_json5("transport/link/tls", json.dumps(self.tls.json()))
        return config
