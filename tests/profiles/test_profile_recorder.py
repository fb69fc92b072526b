"""The recorder a profile adds to record a system (profiles/recorder.py; not test_recorder.py,
which tests/components holds: test modules need distinct names)."""

from __future__ import annotations

from pathlib import Path

from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from profiles.recorder import RECORDER, with_recorder


def test_a_profile_with_a_recorder_extends_the_profile_and_records_the_keys(
    tmp_path: Path,
) -> None:
    path = tmp_path / "recorded.yaml"
    path.write_text(with_recorder(DEPLOY / "sim.yaml", Path("session.mcap"), ("a/*", "b")))
    profile, base = load_profile(path), load_profile(DEPLOY / "sim.yaml")
    assert profile.namespace == base.namespace
    recorder = profile.component(RECORDER)
    assert recorder.role == "recorder" and recorder.restart.policy == "never"
    assert recorder.params == {"path": str(Path("session.mcap").resolve()), "keys": "a/*,b"}
    assert profile.start_order()[0].name == RECORDER  # it starts first
