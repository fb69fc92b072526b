"""What the driver tests share: a hardware profile with one device path changed, the test on the
device's side of a pseudo-terminal, a status query, and a Create stream frame."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import yaml

from launch import query
from messages.status import ComponentStatus
from profiles.deploy_files import DEPLOY
from profiles.profile_files import read_profile_data
from protocols import create_oi
from sim2d.devices.pty_link import PtyLink

if TYPE_CHECKING:
    from tests.components.conftest import System


def driver_system(deployed, tmp_path: Path, name: str, port: Path, **params: object) -> System:
    """deploy/hardware.yaml with ``name``'s port at ``port`` (and ``params``), on a free router
    port."""
    data = read_profile_data(DEPLOY / "hardware.yaml")
    for spec in data["components"]:
        if spec["name"] == name:
            spec["params"] = {**spec.get("params", {}), "port": str(port), **params}
    path = tmp_path / "hardware.yaml"
    path.write_text(yaml.safe_dump(data))
    return deployed(path)


class FakeLink(PtyLink):
    """The test on the device's side of a pseudo-terminal."""

    def read(self) -> bytes:
        try:
            return os.read(self.master, 4096)
        except BlockingIOError:
            return b""

    def write(self, data: bytes) -> None:
        os.write(self.master, data)


STATUS_TIMEOUT_S = 5.0
"""A driver answers its status between two reads of its devices; an arm driver waiting for a
silent servo's answer (the arm tests wait a second) answers it only after."""


def status(system: System, name: str) -> ComponentStatus | None:
    return query.statuses(system.router, system.profile.namespace, STATUS_TIMEOUT_S).get(name)


def frame(left: int, right: int) -> bytes:
    """A stream frame of the two encoder packets."""
    packets = {create_oi.LEFT_ENCODER: left, create_oi.RIGHT_ENCODER: right}
    return create_oi.stream_frame({i: create_oi.packet_data(i, v) for i, v in packets.items()})
