"""A profile written as YAML in a test's folder, and what ``load_profile`` says refusing one: shared
by the tests of profiles."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from profiles.profile import ProfileError, load_profile

PUB = {"name": "pub", "module": "scripted_publisher", "role": "tool"}
"""The smallest component a profile may hold."""


def write(tmp_path: Path, data: object) -> Path:
    path = tmp_path / "profile.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def refusal(tmp_path: Path, data: object) -> str:
    with pytest.raises(ProfileError) as error:
        load_profile(write(tmp_path, data))
    return str(error.value)
