"""Profile validation: every refusal names the file, the field and what was expected."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from profiles.profile import ProfileError, load_profile
from tests.profiles.profile_yaml import PUB, refusal, write


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


def test_a_huge_wrong_value_is_not_echoed_whole(tmp_path: Path) -> None:
    said = refusal(
        tmp_path,
        {
            "namespace": "t",
            "components": [{**PUB, "params": {"rate_hz": {str(i): i for i in range(30_000)}}}],
        },
    )
    assert "components[0].params" in said and len(said) < 1000, said[:2000]


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
