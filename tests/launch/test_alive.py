"""Waiting for a running system's components to come alive (launch/alive.py), on a real router on
loopback: the components present, those still missing named, a router that is not there."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
import zenoh

from launch.alive import NotAlive, wait_alive
from launch.query import Target
from messages import topics
from profiles.endpoints import free_port
from profiles.profile import load_profile

NAMESPACE = "alive"


def target(tmp_path: Path) -> Target:
    profile = tmp_path / "alive.yaml"
    pub = {"name": "ctl", "module": "scripted_publisher", "role": "tool"}
    router = {"router": [f"tcp/127.0.0.1:{free_port()}"]}
    profile.write_text(
        yaml.safe_dump({"namespace": NAMESPACE, "zenoh": router, "components": [pub]})
    )
    return Target.from_profile(profile)


def test_the_wait_ends_once_every_component_is_alive_and_names_those_that_are_not(
    tmp_path: Path,
) -> None:
    where = target(tmp_path)
    said: list[str] = []
    with zenoh.open(load_profile(tmp_path / "alive.yaml").zenoh.router_config()) as router:
        token = router.liveliness().declare_token(topics.liveliness_key(NAMESPACE, "ctl"))
        wait_alive(where, ["ctl"], timeout_s=30.0, say=said.append)
        # Long enough for a liveliness query to answer on a busy machine (0.2 s did not).
        with pytest.raises(NotAlive, match=r"not alive after 2 s: est \(1 of 2 alive\)"):
            wait_alive(where, ["ctl", "est"], timeout_s=2.0, say=said.append)
        token.undeclare()
    assert any("waiting for est to come alive, 1 of 2 so far" in line for line in said), said


def test_with_no_router_the_wait_says_so_and_names_every_component(tmp_path: Path) -> None:
    with pytest.raises(NotAlive, match=r"no router at tcp/127\.0\.0\.1:\d+ .*not alive: ctl, est"):
        wait_alive(target(tmp_path), ["ctl", "est"], timeout_s=0.2, say=print)
