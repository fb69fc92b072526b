"""Where the deploy profiles, the robot descriptions and the lab's files are: ``deploy/``,
beside these packages in the source tree and as package data when installed."""

from pathlib import Path

DEPLOY = Path(__file__).resolve().parent.parent / "deploy"
"""The profiles (YAML), ``robots/`` (the robot descriptions) and ``lab/`` (the lab's files)."""
ROBOTS_DIR = DEPLOY / "robots"
"""The robot descriptions, the zoo (``zoo``)."""
ROBOT_FILE = ROBOTS_DIR / "little_john.yaml"
"""The description of the robot every profile here runs."""


def zoo() -> list[Path]:
    """Every robot description the project ships (deploy/robots/*.yaml), sorted by name."""
    return sorted(ROBOTS_DIR.glob("*.yaml"))
