"""Little John with its servos mapped: ids reversed, offsets and directions of their own."""

from __future__ import annotations

from pathlib import Path

from profiles.deploy_files import ROBOT_FILE

MAPPED = """servos:
  ids: [5, 4, 3, 2, 1]
  offsets: [0.1, 0.0, -0.2, 0.0, 0.3]
  directions: [1, -1, 1, 1, -1]
"""


def mapped_robot(tmp_path: Path, servos: str = MAPPED) -> Path:
    """Little John with its ``servos:`` section replaced by ``servos``."""
    text = ROBOT_FILE.read_text()
    path = tmp_path / "mapped.yaml"
    path.write_text(text[: text.index("servos:")] + servos)
    return path
