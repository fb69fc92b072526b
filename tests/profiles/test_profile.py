"""Profile validation: every refusal names the file, the field and what was expected."""

from __future__ import annotations

import json
import queue
import socket
import time
from pathlib import Path

import pytest
import yaml
import zenoh

from profiles.endpoints import is_local_endpoint
from profiles.profile import ProfileError, ZenohSettings, load_profile

PUB = {"name": "pub", "module": "scripted_publisher", "role": "tool"}


def write(tmp_path: Path, data: object) -> Path:
    path = tmp_path / "profile.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def refusal(tmp_path: Path, data: object) -> str:
    with pytest.raises(ProfileError) as error:
        load_profile(write(tmp_path, data))
    return str(error.value)


def test_a_minimal_profile_gets_safe_defaults(tmp_path: Path) -> None:
    (tmp_path / "robot.yaml").write_text("links: []\n")
    profile = load_profile(
        write(tmp_path, {"namespace": "sim", "robot": "robot.yaml", "components": [PUB]})
    )
    assert profile.robot == tmp_path / "robot.yaml"
    assert profile.clock == "wall"
    assert profile.zenoh.mode == "peer"
    assert profile.zenoh.connect_endpoints == ["tcp/127.0.0.1:7447"]
    assert profile.zenoh.multicast_scouting is False
    spec = profile.component("pub")
    assert spec.restart.policy == "on-failure" and spec.enabled and spec.params == {}
    assert spec.module_path == "components.scripted_publisher"


@pytest.mark.parametrize(
    ("change", "field", "expected"),
    [
        (
            {"components": [{**PUB, "restart": {"policy": "sometimes"}}]},
            "components[0].restart.policy",
            "'never', 'on-failure' or 'always'",
        ),
        (
            {"components": [PUB, {**PUB, "name": "b", "role": "boss"}]},
            "components[1].role",
            "'driver', 'estimator', 'controller' or 'tool'",
        ),
        ({"components": [{**PUB, "colour": "red"}]}, "components[0].colour", "Extra inputs"),
        (
            {"components": [{**PUB, "params": {"gains": {"eta": 1}}}]},
            "components[0].params.gains",
            "valid",
        ),
        ({"components": [PUB, PUB]}, "components[1].name", "already used by components[0]"),
        (
            {"components": [{**PUB, "module": "no_such_component"}]},
            "components[0].module",
            "no module 'components.no_such_component'",
        ),
        (
            {"components": [{**PUB, "restart": {"backoff_initial_s": 2, "backoff_max_s": 1}}]},
            "components[0].restart.backoff_max_s",
            "expected >= backoff_initial_s",
        ),
        ({"components": [{**PUB, "name": "Bad Name"}]}, "components[0].name", "pattern"),
        ({"namespace": "sim/*"}, "namespace", "pattern"),
        ({"components": []}, "components", "at least 1"),
        ({"clock": "sundial"}, "clock", "'wall' or 'sim'"),
        ({"robot": "missing.yaml"}, "robot", "no robot description"),
        ({"zenoh": {"mode": "router"}}, "zenoh.mode", "'client' or 'peer'"),
        (
            {"components": [{**PUB, "after": ["nobody"]}]},
            "components[0].after",
            "'nobody' names no component (have pub)",
        ),
        ({"components": [{**PUB, "after": ["pub"]}]}, "components[0].after", "'pub' is itself"),
        (
            {
                "components": [
                    PUB,
                    {**PUB, "name": "b", "after": ["pub"], "enabled": False},
                    {**PUB, "name": "c", "after": ["b"]},
                ]
            },
            "components[2].after",
            "'b' is not enabled",
        ),
        (
            {"components": [PUB, {**PUB, "name": "drv", "role": "driver", "after": ["pub"]}]},
            "components[1].after",
            "'pub' is a tool, whose role starts after a driver's",
        ),
        (
            {
                "components": [
                    {**PUB, "after": ["b"]},
                    {**PUB, "name": "b", "after": ["c"]},
                    {**PUB, "name": "c", "after": ["pub"]},
                ]
            },
            "components",
            "wait for each other in a circle (pub -> b -> c -> pub)",
        ),
    ],
)
def test_invalid_profiles_name_the_field(
    tmp_path: Path, change: dict[str, object], field: str, expected: str
) -> None:
    message = refusal(tmp_path, {"namespace": "sim", "components": [PUB], **change})
    assert message.startswith(f"{tmp_path / 'profile.yaml'}: invalid profile")
    assert f"  {field}" in message and expected in message, message


def test_missing_namespace_is_named(tmp_path: Path) -> None:
    assert "namespace: Field required" in refusal(tmp_path, {"components": [PUB]})


def test_yaml_syntax_errors_give_the_line(tmp_path: Path) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text("namespace: sim\ncomponents:\n  - {name: pub, module: x\n  - other\n")
    with pytest.raises(ProfileError, match=r"broken\.yaml:5:1: YAML syntax error: expected ','"):
        load_profile(path)


def test_an_alias_bomb_and_a_file_that_is_not_utf8_are_refused_at_once(tmp_path: Path) -> None:
    bomb = tmp_path / "bomb.yaml"
    lines = ['a0: &a0 ["x", "x", "x", "x", "x", "x", "x", "x", "x"]']
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]
    bomb.write_text("\n".join(lines) + "\n")  # 9**9 strings once expanded
    with pytest.raises(ProfileError, match=r"bomb\.yaml: expands to more than 100000 values"):
        load_profile(bomb)
    latin = tmp_path / "latin.yaml"
    latin.write_bytes("namespace: régl\n".encode("latin-1"))
    with pytest.raises(ProfileError, match=r"latin\.yaml: not UTF-8 text \(byte 12\)"):
        load_profile(latin)


def test_a_huge_wrong_value_is_not_echoed_whole(tmp_path: Path) -> None:
    said = refusal(
        tmp_path,
        {
            "namespace": "t",
            "components": [{**PUB, "params": {"rate_hz": {str(i): i for i in range(30_000)}}}],
        },
    )
    assert "components[0].params" in said and len(said) < 1000, said[:2000]


def test_a_profile_that_is_not_a_mapping_or_not_there_is_refused(tmp_path: Path) -> None:
    assert "expected a mapping at the top level, got list" in refusal(tmp_path, [1, 2])
    with pytest.raises(ProfileError, match="cannot read profile"):
        load_profile(tmp_path / "absent.yaml")


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


def test_start_order_is_by_role_and_skips_disabled_components(tmp_path: Path) -> None:
    components = [
        {**PUB, "name": "tool"},
        {**PUB, "name": "ctrl", "role": "controller"},
        {**PUB, "name": "off", "role": "driver", "enabled": False},
        {**PUB, "name": "drv", "role": "driver"},
        {**PUB, "name": "est", "role": "estimator"},
    ]
    profile = load_profile(write(tmp_path, {"namespace": "sim", "components": components}))
    assert [spec.name for spec in profile.start_order()] == ["drv", "est", "ctrl", "tool"]


def test_a_component_may_wait_for_others_of_its_role_or_an_earlier_one(tmp_path: Path) -> None:
    components = [
        {**PUB, "name": "emu", "role": "driver"},
        {**PUB, "name": "drv", "role": "driver", "after": ["emu"]},
        {**PUB, "name": "est", "role": "estimator", "after": ["drv", "emu"]},
    ]
    profile = load_profile(write(tmp_path, {"namespace": "sim", "components": components}))
    assert [profile.start_depth(spec) for spec in profile.components] == [0, 1, 2]


def test_a_profile_extends_another_and_says_only_what_differs(tmp_path: Path) -> None:
    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "robot.yaml").write_text("links: []\n")
    base = {
        "namespace": "sim",
        "robot": "robots/robot.yaml",
        "zenoh": {"router": ["tcp/127.0.0.1:7600"]},
        "components": [
            {**PUB, "params": {"rate_hz": 50.0, "goal_task": "pose"}},
            {
                "name": "ctl",
                "module": "lp_controller",
                "role": "controller",
                "params": {"eta": 0.6},
            },
        ],
    }
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(base))
    child_dir = tmp_path / "variants"
    child_dir.mkdir()
    child = {
        "extends": "../base.yaml",
        "zenoh": {"mode": "client"},
        "components": [
            {"name": "ctl", "module": "cascade_controller"},
            {"name": "pub", "params": {"rate_hz": 10.0}},
            {"name": "extra", "module": "scripted_publisher", "role": "tool", "enabled": False},
        ],
    }
    path = child_dir / "child.yaml"
    path.write_text(yaml.safe_dump(child))
    profile = load_profile(path)
    assert profile.namespace == "sim" and profile.zenoh.mode == "client"
    assert profile.zenoh.router == ["tcp/127.0.0.1:7600"]
    assert profile.robot == tmp_path / "robots" / "robot.yaml"  # relative to base.yaml
    assert [spec.name for spec in profile.components] == ["pub", "ctl", "extra"]
    assert profile.component("ctl").module == "cascade_controller"
    assert profile.component("ctl").params == {"eta": 0.6}
    assert profile.component("pub").params == {"rate_hz": 10.0, "goal_task": "pose"}
    assert [spec.name for spec in profile.start_order()] == ["ctl", "pub"]


def test_extends_that_is_missing_or_circular_is_refused(tmp_path: Path) -> None:
    assert "extends: no profile at" in refusal(tmp_path, {"extends": "nowhere.yaml"})
    (tmp_path / "a.yaml").write_text(yaml.safe_dump({"extends": "b.yaml"}))
    (tmp_path / "b.yaml").write_text(yaml.safe_dump({"extends": "a.yaml"}))
    with pytest.raises(ProfileError, match="in a circle"):
        load_profile(tmp_path / "a.yaml")


def test_an_invalid_override_names_its_field(tmp_path: Path) -> None:
    (tmp_path / "base.yaml").write_text(yaml.safe_dump({"namespace": "sim", "components": [PUB]}))
    message = refusal(
        tmp_path,
        {
            "extends": "base.yaml",
            "components": [{"name": "pub", "restart": {"policy": "sometimes"}}],
        },
    )
    assert "components[0].restart.policy" in message


@pytest.mark.parametrize(
    ("remap", "complaint"),
    [
        ({"control/goal": "robot/state"}, "control/goal carries Goal and robot/state RobotState"),
        ({"control/goal": "goal/requests"}, "'goal/requests' is not a topic"),
    ],
)
def test_a_remap_must_name_topics_of_one_message_type(
    tmp_path: Path, remap: dict[str, str], complaint: str
) -> None:
    path = tmp_path / "remap.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "namespace": "remap",
                "components": [
                    {
                        "name": "estimator",
                        "module": "state_estimator",
                        "role": "estimator",
                        "remap": remap,
                    }
                ],
            }
        )
    )
    with pytest.raises(ProfileError, match=r"components\[0\]\.remap: ") as error:
        load_profile(path)
    assert complaint in str(error.value)
