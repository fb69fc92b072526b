"""Authentication and per-topic write rights on a launched system (``zenoh.access``)."""

from __future__ import annotations

import json
import subprocess
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
import yaml
import zenoh

from launch import query
from messages import codec, topics
from messages.goal import Goal
from messages.header import Header
from profiles.deploy_files import ROBOT_FILE
from profiles.network import ZenohSettings
from profiles.profile import ProfileError, load_profile
from tests.launch.conftest import free_port
from tests.parsimony.in_process import completed

if TYPE_CHECKING:
    from tests.launch.conftest import LaunchFixture


def access_profile(directory: Path) -> Path:
    (directory / "credentials.txt").write_text(
        "# user:password\noperator:op-secret\nviewer:view-secret\nctl:ctl-secret\n"
    )
    profile = {
        "namespace": "test",
        "robot": str(ROBOT_FILE),
        "zenoh": {
            "mode": "client",
            "router": [f"tcp/127.0.0.1:{free_port()}"],
            "access": {
                "credentials": "credentials.txt",
                "writers": {"control/goal": ["operator"]},
                "parameters": {"ctl": ["operator"]},
            },
        },
        "components": [{"name": "ctl", "module": "lp_controller", "role": "controller"}],
    }
    path = directory / "profile.yaml"
    path.write_text(yaml.safe_dump(profile))
    return path


def goal_payload() -> bytes:
    header = Header(stamp_ns=time.time_ns(), frame="world", seq=0, source="test")
    return codec.encode(Goal(header=header, task="position", position=(0.6, 0.0, 0.4)))


def goals_received(session: zenoh.Session) -> int:
    return query.statuses(session, "test")["ctl"].counters["received.control/goal"]


def test_only_the_writers_of_a_topic_may_put_and_strangers_cannot_connect(
    tmp_path: Path, launch: LaunchFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = access_profile(tmp_path)
    settings = load_profile(path).zenoh
    launched = launch(path)
    launched.wait_for(r"\[launch\] ctl alive")

    monkeypatch.setenv("PARSIMONY_USER", "viewer")
    with zenoh.open(settings.client_config()) as viewer:
        assert goals_received(viewer) == 0
        viewer.put(topics.CONTROL_GOAL.key("test"), goal_payload())
        # The status query travels the same link after the put: its answer comes after the
        # router has dealt with the put.
        assert goals_received(viewer) == 0
    with zenoh.open(settings.client_config("operator")) as operator:
        operator.put(topics.CONTROL_GOAL.key("test"), goal_payload())
        deadline = time.monotonic() + 10.0
        while goals_received(operator) != 1:
            assert time.monotonic() < deadline, "the operator's goal did not arrive"

    anonymous = ZenohSettings(mode="client", router=settings.router)
    with pytest.raises(zenoh.ZError):
        zenoh.open(anonymous.client_config())
    wrong = settings.client_config("viewer")
    wrong.insert_json5("transport/auth/usrpwd/password", json.dumps("guess"))
    with pytest.raises(zenoh.ZError):
        zenoh.open(wrong)
    assert launched.stop() == 0


def param(user: str, profile: Path, *argv: str) -> subprocess.CompletedProcess[str]:
    """`parsimony param ARGV` run by ``user`` (by its entry point in the test's process)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("PARSIMONY_USER", user)
        return completed("param", *argv, "--profile", str(profile))


def test_only_the_users_a_rule_names_may_set_a_components_parameters(
    tmp_path: Path, launch: LaunchFixture
) -> None:
    path = access_profile(tmp_path)
    launched = launch(path)
    launched.wait_for(r"\[launch\] ctl alive")
    why = "viewer may not set ctl's parameters (zenoh.access.parameters)"

    refused = param("viewer", path, "set", "ctl", "stale_timeout_s", "0.25")
    assert refused.returncode == 1 and refused.stdout == "", refused
    assert (
        refused.stderr.startswith(f"param set refused: {why}")
        and len(refused.stderr.splitlines()) == 1
    ), refused.stderr
    (tmp_path / "ctl.yaml").write_text("stale_timeout_s: 0.25\n")
    refused = param("viewer", path, "load", "ctl", str(tmp_path / "ctl.yaml"))
    assert refused.returncode == 1 and f"param load refused: {why}" in refused.stderr, refused
    unchanged = param("viewer", path, "get", "ctl", "stale_timeout_s")
    assert unchanged.stdout.strip() == "ctl.stale_timeout_s = 0.5", unchanged

    accepted = param("operator", path, "set", "ctl", "stale_timeout_s", "0.25")
    assert accepted.stdout.strip() == "ctl.stale_timeout_s = 0.25", accepted
    assert (
        param("viewer", path, "get", "ctl", "stale_timeout_s").stdout.strip()
        == "ctl.stale_timeout_s = 0.25"
    )
    assert launched.stop() == 0


def test_an_access_profile_must_run_in_client_mode_and_name_known_users(tmp_path: Path) -> None:
    path = access_profile(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["zenoh"]["mode"] = "peer"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ProfileError, match="set mode: client"):
        load_profile(path)
    data["zenoh"]["mode"] = "client"
    data["zenoh"]["access"]["writers"] = {"control/goal": ["mallory"]}
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ProfileError, match=r"writers.control/goal: \['mallory'\] not in"):
        load_profile(path)
    data["zenoh"]["access"]["writers"] = {}
    data["components"][0]["name"] = "nobody"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ProfileError, match="'nobody' has no line in"):
        load_profile(path)
