"""The commands' ``--robot``: a robot of the zoo by name (``deploy/robots/NAME.yaml``) or a
robot description's file."""

from __future__ import annotations

import argparse
from pathlib import Path

from profiles.deploy_files import ROBOT_FILE, ROBOTS_DIR, zoo


def robot_file(text: str) -> Path:
    """``text`` as a robot description's file: a path as given (it names a directory or ends
    in .yaml), else the zoo's robot of that name; ``ArgumentTypeError`` naming the zoo when
    it has none."""
    path = Path(text)
    if path.suffix in (".yaml", ".yml") or len(path.parts) > 1:
        return path
    found = ROBOTS_DIR / f"{text}.yaml"
    if not found.is_file():
        names = ", ".join(p.stem for p in zoo())
        raise argparse.ArgumentTypeError(
            f"no robot {text!r} in the zoo ({names}); or give a description's path"
        )
    return found


def add_robot_option(
    parser: argparse.ArgumentParser,
    help_text: str = "robot description: a zoo name or a file",
    default: Path | None = ROBOT_FILE,
) -> None:
    """``--robot NAME|PATH`` on ``parser`` (``robot_file``), Little John's by default."""
    parser.add_argument(
        "--robot", type=robot_file, default=default, metavar="NAME|PATH", help=help_text
    )
