"""`parsimony view` obeys ``zenoh.access``: a view whose user may not write goal/request offers
its clients no publishing (Foxglove's own client is told so when it tries), one whose user may
offers it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
import zenoh

from profiles.endpoints import free_port
from profiles.profile import load_profile
from tests.foxglove_client.client import DEADLINE_S, FoxgloveClient, missing

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


def view_as(user: str, profile: Path) -> tuple[subprocess.Popen, str, str]:
    """``parsimony view`` run by ``user``, its address and the line that says it listens."""
    port = free_port()
    view = subprocess.Popen([sys.executable, "-m", "parsimony.cli", "view", str(profile),
                             "--port", str(port)], text=True, stderr=subprocess.PIPE,
                            env={**os.environ, "PARSIMONY_USER": user})  # fmt: skip
    assert view.stderr is not None
    return view, f"ws://127.0.0.1:{port}", view.stderr.readline()


def stop(view: subprocess.Popen) -> None:
    view.send_signal(signal.SIGTERM)
    _, err = view.communicate(timeout=DEADLINE_S)
    assert view.returncode == 0, err


def test_a_view_whose_user_may_not_write_goals_offers_no_publishing(guarded: Path) -> None:
    assert not missing(), missing()
    view, address, line = view_as("viewer", guarded)
    try:
        assert "no publishing: viewer may not write goal/request" in line, line
        with FoxgloveClient(address) as client:
            info = client.server_info()
            assert "clientPublish" not in info["capabilities"]
            assert "parameters" in info["capabilities"]
            client.send("advertise", topic=f"{NAMESPACE}/goal/request", encoding="json",
                        schemaName="foxglove.PoseInFrame")  # fmt: skip
            refused = client.wait_for(lambda e: e["event"] == "status", "the server's answer")
            assert "does not support clientPublish" in refused["message"]
    finally:
        stop(view)
    view, address, line = view_as("operator", guarded)
    try:
        assert "goals from clients on goal/request" in line, line
        with FoxgloveClient(address) as client:
            assert "clientPublish" in client.server_info()["capabilities"]
    finally:
        stop(view)
