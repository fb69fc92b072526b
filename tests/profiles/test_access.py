"""profiles.access: who may set which component's parameters (``access.parameters``)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from pydantic import ValidationError

from profiles.access import AccessSettings
from profiles.profile import ProfileError, load_profile


@pytest.fixture
def credentials(tmp_path: Path) -> Path:
    path = tmp_path / "credentials.txt"
    path.write_text("operator:a\nviewer:b\nguest:c\n")
    return path


def test_a_component_named_its_users_else_every_components_else_anyone(
    credentials: Path,
) -> None:
    access = AccessSettings(
        credentials=credentials, parameters={"*": ["operator"], "camera": ["operator", "guest"]}
    )
    assert access.may_set("controller", "operator") and not access.may_set("controller", "guest")
    assert access.may_set("camera", "guest") and not access.may_set("camera", "viewer")
    free = AccessSettings(credentials=credentials, parameters={"camera": ["operator"]})
    assert free.may_set("controller", "viewer") and not free.may_set("camera", "viewer")


def test_a_setter_must_have_credentials(credentials: Path) -> None:
    with pytest.raises(ValidationError, match=r"parameters.camera: \['mallory'\] not in"):
        AccessSettings(credentials=credentials, parameters={"camera": ["mallory"]})


def test_a_rule_must_name_a_component_of_the_profile(tmp_path: Path) -> None:
    (tmp_path / "credentials.txt").write_text("operator:a\nguest:b\nctl:c\ncam:d\n")
    data = {
        "namespace": "test",
        "zenoh": {
            "mode": "client",
            "access": {
                "credentials": "credentials.txt",
                "parameters": {"*": ["operator"], "clt": ["guest"]},
            },
        },
        "components": [
            {"name": name, "module": "scripted_publisher", "role": "tool"}
            for name in ("ctl", "cam")
        ],
    }
    path = tmp_path / "profile.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(
        ProfileError,
        match=r"zenoh.access.parameters.clt: names no component "
        r"of the profile \(have ctl, cam\)",
    ):
        load_profile(path)
    data["zenoh"]["access"]["parameters"] = {"*": ["operator"], "ctl": ["guest"]}
    path.write_text(yaml.safe_dump(data))
    access = load_profile(path).zenoh.access
    assert access is not None and access.may_set("ctl", "guest")
