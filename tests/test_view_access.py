"""`parsimony view` obeys ``zenoh.access``: a view whose user may not write goal/request offers
its clients no publishing (Foxglove's own client is told so when it tries), one whose user may
offers it."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
import zenoh

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
    """A profile whose goal/request only the operator may write, and its router."""
    users = {"operator": "op-secret", "viewer": "view-secret", "x": "x-secret"}
    (tmp_path / "credentials.txt").write_text("".join(f"{u}:{p}\n" for u, p in users.items()))
    path = tmp_path / "guarded.yaml"
    path.write_text(yaml.safe_dump({
        "namespace": NAMESPACE,
        "zenoh": {"mode": "client", "router": [f"tcp/127.0.0.1:{free_port()}"],
                  "access": {"credentials": "credentials.txt",
                             "writers": {"goal/request": ["operator"]}}},
        "components": [{"name": "x", "module": "scripted_publisher", "role": "tool"}],
    }))  # fmt: skip
    with zenoh.open(load_profile(path).zenoh.router_config(NAMESPACE)):
        yield path


def view_as(user: str, profile: Path) -> contextlib.AbstractContextManager[RunningView]:
    """``parsimony view`` run by ``user``."""
    return running_view(profile, env={**os.environ, "PARSIMONY_USER": user},
                        timeout_s=DEADLINE_S)  # fmt: skip


def test_a_view_whose_user_may_not_write_goals_offers_no_publishing(guarded: Path) -> None:
    assert not missing(), missing()
    with view_as("viewer", guarded) as view:
        line = view.live_line
        assert "no publishing: viewer may not write goal/request" in line, line
        with FoxgloveClient(view.address) as client:
            info = client.server_info()
            assert "clientPublish" not in info["capabilities"]
            assert "parameters" in info["capabilities"]
            client.send("advertise", topic=f"{NAMESPACE}/goal/request", encoding="json",
                        schemaName="foxglove.PoseInFrame")  # fmt: skip
            refused = client.wait_for(lambda e: e["event"] == "status", "the server's answer")
            assert "does not support clientPublish" in refused["message"]
    assert view.process.returncode == 0, view.err
    with view_as("operator", guarded) as view:
        assert "goals from clients on goal/request" in view.live_line, view.live_line
        with FoxgloveClient(view.address) as client:
            assert "clientPublish" in client.server_info()["capabilities"]
    assert view.process.returncode == 0, view.err
