"""A profile's YAML files (profiles/profile_files.py): read safely, ``extends`` resolved and
merged, every refusal naming the file and the field."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from profiles import profile_files
from profiles.deploy_files import DEPLOY
from profiles.profile import ProfileError, load_profile
from tests.profiles.profile_yaml import PUB, refusal


def test_yaml_syntax_errors_give_the_line(tmp_path: Path) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text("namespace: sim\ncomponents:\n  - {name: pub, module: x\n  - other\n")
    with pytest.raises(ProfileError, match=r"broken\.yaml:5:1: YAML syntax error: expected ','"):
        load_profile(path)


@pytest.mark.parametrize("path", sorted(DEPLOY.glob("**/*.yaml")), ids=lambda path: path.name)
def test_a_profile_is_read_as_pyyaml_reads_it(path: Path) -> None:
    """libyaml's parser, which reads profiles (several times faster), builds what PyYAML's does."""
    assert profile_files._read_yaml(path) == yaml.safe_load(path.read_text())


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


def test_a_profile_that_is_not_a_mapping_or_not_there_is_refused(tmp_path: Path) -> None:
    assert "expected a mapping at the top level, got list" in refusal(tmp_path, [1, 2])
    with pytest.raises(ProfileError, match="cannot read profile"):
        load_profile(tmp_path / "absent.yaml")


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
