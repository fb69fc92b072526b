"""profiles.access: who may set which component's parameters (``access.parameters``)."""

from __future__ import annotations

from pathlib import Path

import pytest
from pydantic import ValidationError

from profiles.access import AccessSettings


@pytest.fixture
def credentials(tmp_path: Path) -> Path:
    path = tmp_path / "credentials.txt"
    path.write_text("operator:a\nviewer:b\nguest:c\n")
    return path


def test_a_component_named_its_users_else_every_components_else_anyone(
    credentials: Path,
) -> None:
    access = AccessSettings(credentials=credentials,
                            parameters={"*": ["operator"], "camera": ["operator", "guest"]})
    assert access.may_set("controller", "operator") and not access.may_set("controller", "guest")
    assert access.may_set("camera", "guest") and not access.may_set("camera", "viewer")
    free = AccessSettings(credentials=credentials, parameters={"camera": ["operator"]})
    assert free.may_set("controller", "viewer") and not free.may_set("camera", "viewer")


def test_a_setter_must_have_credentials(credentials: Path) -> None:
    with pytest.raises(ValidationError, match=r"parameters.camera: \['mallory'\] not in"):
        AccessSettings(credentials=credentials, parameters={"camera": ["mallory"]})
