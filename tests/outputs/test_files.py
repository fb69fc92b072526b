"""The files a command writes (outputs/files.py): never an input, never an existing one without
--force, and whole or not at all."""

from __future__ import annotations

from pathlib import Path

import pytest

from outputs.files import writable_output, written_whole


def test_an_output_that_is_an_input_or_exists_without_force_is_refused(tmp_path: Path) -> None:
    given, out = tmp_path / "in.mcap", tmp_path / "out.json"
    given.write_text("x")
    assert writable_output(out, [given], force=False) is None
    assert "is also an input" in writable_output(given, [given], force=True)
    (tmp_path / "link.mcap").symlink_to(given)
    assert "is also an input" in writable_output(tmp_path / "link.mcap", [given], force=True)
    out.write_text("old")
    assert writable_output(out, [given], force=False) == f"{out} exists; give --force to replace it"
    assert writable_output(out, [given], force=True) is None


def test_an_output_is_replaced_whole_or_left_as_it_was(tmp_path: Path) -> None:
    out = tmp_path / "report.json"
    out.write_text("old")
    with pytest.raises(RuntimeError), written_whole(out) as partial:
        partial.write_text("half")
        raise RuntimeError("failed half way")
    assert out.read_text() == "old" and list(tmp_path.iterdir()) == [out]
    with written_whole(out) as partial:
        partial.write_text("new")
        assert out.read_text() == "old"
    assert out.read_text() == "new" and list(tmp_path.iterdir()) == [out]
