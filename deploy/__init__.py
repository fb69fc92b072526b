"""Deploy profiles, the robot descriptions and the launcher."""

from pathlib import Path

DEPLOY = Path(__file__).resolve().parent
"""This folder: the profiles, the robot descriptions, the lab's files."""
ROBOT_FILE = DEPLOY / "robots" / "little_john.yaml"
"""The description of the robot every profile here runs."""
