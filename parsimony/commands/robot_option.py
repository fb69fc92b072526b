"""The commands' ``--robot``: a robot of the zoo by name (``deploy/robots/NAME.yaml``) or a
robot description's file."""

from __future__ import annotations

import argparse
from pathlib import Path

from profiles.deploy_files import DEPLOY

ROBOTS = DEPLOY / "robots"
"""The zoo: one description per robot, named by its file's stem."""


def robot_file(text: str) -> Path:
    """``text`` as a robot description's file: a path as given (it names a directory or ends
    in .yaml), else the zoo's robot of that name; ``ArgumentTypeError`` naming the zoo when
    it has none."""
    path = Path(text)
    if path.suffix in (".yaml", ".yml") or len(path.parts) > 1:
        return path
    found = ROBOTS / f"{text}.yaml"
    if not found.is_file():
        zoo = ", ".join(sorted(p.stem for p in ROBOTS.glob("*.yaml")))
        raise argparse.ArgumentTypeError(
            f"no robot {text!r} in the zoo ({zoo}); or give a description's path"
        )
    return found
